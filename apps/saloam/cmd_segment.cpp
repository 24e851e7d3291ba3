// `saloam segment`: labels the raw scans of a sequence with the segmentation
// network and writes SemanticKITTI .label files (see runs/segment_run.hpp),
// a picture of one scan coloured by predicted class, and, when ground-truth
// labels are at hand, the per-class IoU.

#include <algorithm>
#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/runs/segment_run.hpp"

namespace saloam::cli {
namespace {

namespace fs = std::filesystem;

struct SegmentArgs {
  std::string sequence;
  std::string out;
  std::string frames;
  std::string truth;
  bool no_score = false;
  std::optional<std::size_t> picture;
  SegmentOptions segmenter;
  ConfigOptions config;
};

/// --truth, else SEQ/labels_gt (a simulated sequence's truth), else SEQ/labels.
std::optional<fs::path> truth_folder(const SegmentArgs& args) {
  if (args.no_score) return std::nullopt;
  if (!args.truth.empty()) return fs::path(args.truth);
  std::error_code error;
  for (const char* name : {"labels_gt", "labels"})
    if (const auto folder = fs::path(args.sequence) / name; fs::is_directory(folder, error)) return folder;
  return std::nullopt;
}

void print_score(const SegmentationScore& score, const fs::path& truth) {
  std::cout << fmt::format("against {}: mIoU {:.1f} %, accuracy {:.1f} %\n", truth.string(), 100 * score.miou(),
                           100 * score.accuracy());
  for (int c = 1; c < kNumLearningClasses; ++c)
    if (score.truth_count(c) > 0)
      std::cout << fmt::format("  {:<14} IoU {:5.1f} %  ({} points)\n", learning_class_name(static_cast<std::uint8_t>(c)),
                               100 * score.iou(c), score.truth_count(c));
}

int run_segment(const SegmentArgs& args) {
  const SaloamConfig config = args.config.resolve();
  const SegmenterSpec spec =
      read_segmenter_spec(segmenter_description_path(args.segmenter.segmenter, args.segmenter.projection, config));
  SequenceOptions sequence_options;
  sequence_options.ignore_labels = true;
  const SequenceReader reader(args.sequence, sequence_options);
  SequenceFolderSource folder(reader);
  SegmentedSource source(
      folder, [&] { return std::make_unique<Segmenter>(spec, segmentation_plugin_path(), config.odometry.features); },
      config.segmentation.workers, config.segmentation.lookahead);

  SegmentRunOptions options;
  std::tie(options.first_frame, options.end_frame) = FrameRange::parse(args.frames).clip(reader.size());
  options.truth = truth_folder(args);
  options.picture_frame = args.picture;
  options.show_progress = spdlog::get_level() <= spdlog::level::info;
  const SegmentRunResult result = run_segmentation(source, args.out, options);

  auto ms = result.segment_ms;
  std::sort(ms.begin(), ms.end());
  const double median = ms.empty() ? 0.0 : ms[ms.size() / 2];
  std::cout << fmt::format("{} scans, {} points, network stage median {:.1f} ms/scan ({:.1f} Hz per worker, {} "
                           "worker(s)); model {}\n",
                           result.frames, result.points, median, median > 0 ? 1000.0 / median : 0.0,
                           config.segmentation.workers, spec.file.string());
  if (result.score) print_score(*result.score, *options.truth);
  std::cout << fmt::format("wrote {} .label files to {}; picture {}\n", result.frames, args.out, result.picture.string());
  if (result.interrupted) {
    spdlog::warn("interrupted: {} scans labelled", result.frames);
    return 130;
  }
  return 0;
}

const CommandRegistration kRegistration{Command{
    "segment", "Label raw scans with the segmentation network (SemanticKITTI .label files)", 25, [](CLI::App& app) {
      auto args = std::make_shared<SegmentArgs>();
      app.add_option("SEQ_DIR", args->sequence, "Sequence folder (velodyne/; labels are not read but to score)")
          ->required();
      app.add_option("--out", args->out, "Folder for the .label files (and segment_NNNNNN.png)")->required();
      app.add_option("--frames", args->frames, "Frame range A:B (B exclusive; A: = to the end)");
      app.add_option("--truth", args->truth,
                     "Ground-truth .label folder to score against (default: SEQ/labels_gt, else SEQ/labels)");
      app.add_flag("--no-score", args->no_score, "Do not score against ground truth");
      app.add_option("--picture", args->picture, "Frame drawn coloured by predicted class (default: the middle one)")
          ->check(non_negative_integer());
      app.add_option("--segmenter", args->segmenter.segmenter,
                     "Segmentation model: a description (.yaml) or a TorchScript network (.pt); default: the shipped one");
      app.add_option("--projection", args->segmenter.projection, "Description (.yaml) of a --segmenter TorchScript network");
      args->config.add_to(app);
      return [args] { return run_segment(*args); };
    }}};

}  // namespace
}  // namespace saloam::cli
