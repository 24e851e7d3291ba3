#include "saloam/runs/segment_run.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/sim/render.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

void refuse_input_folder(const SegmentedSource& source, const fs::path& out_dir) {
  const auto folder = source.folder();
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

}  // namespace

SegmentRunResult run_segmentation(SegmentedSource& source, const fs::path& out_dir, const SegmentRunOptions& options) {
  const std::size_t end = std::min(options.end_frame, source.size());
  if (options.first_frame >= end) throw ConfigError("segment: the frame range holds no scan");
  refuse_input_folder(source, out_dir);
  create_folder(out_dir);
  const std::size_t picture = options.picture_frame.value_or(options.first_frame + (end - options.first_frame) / 2);
  SegmentRunResult result;
  if (options.truth) result.score.emplace();
  ProgressBar progress(end - options.first_frame, "segment", options.show_progress);
  for (std::size_t i = options.first_frame; i < end; ++i) {
    if (stop_requested()) {
      result.interrupted = true;
      break;
    }
    const LabelledCloud cloud = source.scan(i);
    write_scan_labels(out_dir / (frame_name(i) + ".label"), cloud);
    if (result.score) result.score->add(truth_labels(*options.truth, i, cloud.size()), cloud.label);
    if (i == picture) {
      result.picture = out_dir / fmt::format("segment_{}.png", frame_name(i));
      render_range_image(cloud, result.picture);
    }
    ++result.frames;
    result.points += cloud.size();
    progress.advance();
  }
  progress.finish();
  result.segment_ms = source.segment_ms();
  return result;
}

}  // namespace saloam
