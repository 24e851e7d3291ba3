// `saloam odom`: semantic-assisted LOAM odometry over a sequence folder.
// Writes poses.txt (KITTI camera-frame convention, comparable with the
// ground truth), poses_tum.txt (LiDAR frame) and timing.json. Poses are
// flushed frame by frame so an interrupted run keeps what it computed
// (see pipeline/odometry_run.hpp).

#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/runs/odometry_run.hpp"

namespace saloam::cli {
namespace {

struct OdomOptions {
  std::string sequence;
  std::string out;
  std::string labels;
  std::string frames;
  bool no_semantics = false;
  bool no_calib = false;
  ConfigOptions config;
};

int run_odom(const OdomOptions& options) {
  SaloamConfig config = options.config.resolve();
  if (options.no_semantics) config.odometry.use_semantics = false;
  SequenceOptions seq_options;
  if (!options.labels.empty()) seq_options.labels_dir = options.labels;
  seq_options.ignore_labels = !config.odometry.use_semantics;
  const SequenceReader reader(options.sequence, seq_options);
  OdometryRunOptions run_options;
  run_options.no_calib = options.no_calib;
  std::tie(run_options.first_frame, run_options.end_frame) = FrameRange::parse(options.frames).clip(reader.size());

  const std::filesystem::path out_dir(options.out);
  const OdometryRunResult result = run_odometry(reader, config.odometry, out_dir, run_options);
  const double median_ms = result.median_frame_ms();
  std::cout << fmt::format("{} frames, {} registration failures, median {:.1f} ms/frame ({:.1f} Hz)\n", result.frames,
                           result.registration_failures, median_ms, median_ms > 0 ? 1000.0 / median_ms : 0.0);
  std::cout << fmt::format("wrote {}, {}, {}\n", (out_dir / "poses.txt").string(),
                           (out_dir / "poses_tum.txt").string(), (out_dir / "timing.json").string());
  if (result.interrupted) {
    spdlog::warn("interrupted: {} frames written", result.frames);
    return 130;
  }
  return 0;
}

const CommandRegistration kRegistration{Command{
    "odom", "Semantic-assisted LOAM odometry over a sequence folder", 30, [](CLI::App& app) {
      auto options = std::make_shared<OdomOptions>();
      app.add_option("SEQ_DIR", options->sequence, "Sequence folder (velodyne/, labels/, calib.txt, times.txt)")
          ->required();
      app.add_option("--out", options->out, "Output folder for poses.txt, poses_tum.txt, timing.json")->required();
      app.add_option("--labels", options->labels, "Folder of .label files to use instead of SEQ_DIR/labels");
      app.add_flag("--no-semantics", options->no_semantics,
                   "Label-agnostic run with plain voxel grid (FLOAM-like baseline)");
      app.add_option("--frames", options->frames, "Frame range A:B (B exclusive; A: = to the end)");
      add_no_calib_flag(app, options->no_calib);
      options->config.add_to(app);
      return [options] { return run_odom(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
