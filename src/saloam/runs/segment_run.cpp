#include "saloam/runs/segment_run.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/viz/range_image.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

void refuse_input_folder(const FrameSource& source, const fs::path& out_dir) {
  const auto& folder = source.info().folder;
  if (!folder) return;
  std::error_code error;
  for (const char* labels : {"labels", "labels_gt"})
    if (fs::exists(out_dir, error) && fs::equivalent(*folder / labels, out_dir, error))
      throw InputError(out_dir, "is the sequence's own labels folder: write predictions elsewhere (never over an input)");
}

std::vector<std::uint16_t> truth_labels(const fs::path& folder, std::size_t frame, std::size_t points) {
  const fs::path file = folder / (frame_name(frame) + ".label");
  const auto raw = read_label_file(file);
  if (raw.size() != points)
    throw InputError(file, fmt::format("{} labels for a scan of {} points", raw.size(), points));
  std::vector<std::uint16_t> labels(raw.size());
  std::transform(raw.begin(), raw.end(), labels.begin(), [](std::uint32_t v) { return static_cast<std::uint16_t>(v & 0xFFFF); });
  return labels;
}

std::vector<StageTime> segmentation_times(const FrameSource& source) {
  for (auto& stage : source.stage_times())
    if (stage.name == "segmentation") return stage.per_frame;
  return {};
}

}  // namespace

SegmentRunResult run_segmentation(FrameSource& source, const fs::path& out_dir, const SegmentRunOptions& options) {
  if (!source.info().has_labels) throw std::logic_error("run_segmentation: a source with labels expected");
  refuse_input_folder(source, out_dir);
  create_folder(out_dir);
  const std::size_t first = source.info().first_frame;
  const std::size_t picture = options.picture_frame.value_or(first + source.size() / 2);
  SegmentRunResult result;
  if (options.truth) result.score.emplace();
  ProgressBar progress(source.size(), "segment", options.show_progress);
  for (std::size_t i = 0; i < source.size(); ++i) {
    if (stop_requested()) {
      result.interrupted = true;
      break;
    }
    const LabelledCloud cloud = source.scan(i);
    const std::size_t frame = first + i;
    write_scan_labels(out_dir / (frame_name(frame) + ".label"), cloud);
    if (result.score) result.score->add(truth_labels(*options.truth, frame, cloud.size()), cloud.label);
    if (frame == picture) {
      result.picture = out_dir / fmt::format("segment_{}.png", frame_name(frame));
      render_range_image(cloud, result.picture, options.picture_elevations_deg);
    }
    ++result.frames;
    result.points += cloud.size();
    progress.advance();
  }
  progress.finish();
  result.segment_times = segmentation_times(source);
  if (result.score) {
    nlohmann::json score = result.score->to_json();
    score["truth"] = fs::absolute(*options.truth).lexically_normal().string();
    score["frames"] = result.frames;
    score["interrupted"] = result.interrupted;
    result.score_file = out_dir / "score.json";
    write_file_atomically(result.score_file, score.dump(1) + '\n');
  }
  return result;
}

}  // namespace saloam
