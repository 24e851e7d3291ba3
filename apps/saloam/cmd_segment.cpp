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
#include "saloam/core/profiling.hpp"
#include "saloam/runs/segment_run.hpp"
#include "saloam/sim/lidar.hpp"

namespace saloam::cli {
namespace {

namespace fs = std::filesystem;

struct SegmentArgs {
  SourceArgs source;  ///< --segment is implied
  std::string out;
  std::string truth;
  bool no_score = false;
  std::optional<std::size_t> picture;
  ConfigOptions config;
};

/// --truth, else SEQ/labels_gt (a simulated sequence's truth), else SEQ/labels.
std::optional<fs::path> truth_folder(const SegmentArgs& args) {
  if (args.no_score) return std::nullopt;
  if (!args.truth.empty()) return fs::path(args.truth);
  std::error_code error;
  for (const char* name : {"labels_gt", "labels"})
    if (const auto folder = fs::path(args.source.path) / name; fs::is_directory(folder, error)) return folder;
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

int run_segment(SegmentArgs args) {
  PathRules rules;
  args.source.add_inputs(rules).input("--truth", args.truth).output("--out", args.out, OutputUse::kFolder).check();
  SaloamConfig config = args.config.resolve();
  args.source.segment.segment = true;
  args.source.no_calib = true;  // labels need no calibration
  const std::unique_ptr<FrameSource> source = args.source.open(false, config);
  SegmentRunOptions options;
  options.truth = truth_folder(args);
  options.picture_frame = args.picture;
  options.picture_elevations_deg = LidarModel::hdl64e().elevation_deg;
  options.show_progress = spdlog::get_level() <= spdlog::level::info;
  const SegmentRunResult result = run_segmentation(*source, args.out, options);

  const Summary wall = summarize(column(result.segment_times, &StageTime::wall_ms));
  const Summary cpu = summarize(column(result.segment_times, &StageTime::cpu_ms));
  std::cout << fmt::format("{} scans, {} points; segmentation stage per scan: median {:.1f} ms CPU, {:.1f} ms wall ({} "
                           "worker(s))\n",
                           result.frames, result.points, cpu.median, wall.median, config.segmentation.workers);
  if (result.score) {
    print_score(*result.score, *options.truth);
    std::cout << fmt::format("score with its confusion matrix: {}\n", result.score_file.string());
  }
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
      args->source.add_to(app, "Sequence folder (velodyne/; labels are read only to score)");
      app.add_option("--out", args->out, "Folder for the .label files (and segment_NNNNNN.png)")->required();
      app.add_option("--truth", args->truth,
                     "Ground-truth .label folder to score against (default: SEQ/labels_gt, else SEQ/labels)");
      app.add_flag("--no-score", args->no_score, "Do not score against ground truth");
      app.add_option("--picture", args->picture, "Frame drawn coloured by predicted class (default: the middle one)")
          ->check(non_negative_integer());
      args->config.add_to(app);
      return [args] { return run_segment(*args); };
    }}};

}  // namespace
}  // namespace saloam::cli
