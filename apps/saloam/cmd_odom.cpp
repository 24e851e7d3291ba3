// `saloam odom`: semantic-assisted LOAM odometry over a sequence folder.
// Writes poses.txt (KITTI camera-frame convention, comparable with the
// ground truth), poses_tum.txt (LiDAR frame) and timing.json. Poses are
// flushed frame by frame so an interrupted run keeps what it computed
// (see runs/odometry_run.hpp).

#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "live_serving.hpp"
#include "saloam/runs/odometry_run.hpp"

namespace saloam::cli {
namespace {

struct OdomOptions {
  SourceArgs source;
  std::string out;
  bool no_semantics = false;
  ServeOptions serve;
  ConfigOptions config;
};

int run_odom(const OdomOptions& options) {
  PathRules rules;
  options.source.add_inputs(rules).output("--out", options.out, OutputUse::kFolder).check();
  SaloamConfig config = options.config.resolve();
  if (options.no_semantics) config.odometry.use_semantics = false;
  const std::unique_ptr<FrameSource> source = options.source.open(!config.odometry.use_semantics, config);
  const std::filesystem::path out_dir(options.out);
  OdometryRunOptions run_options;
  std::unique_ptr<LiveServing> live;
  if (options.serve.serve) {
    live = std::make_unique<LiveServing>(options.source.path, "odom", options.serve.port);
    run_options.follow = live->follower();
  }
  const OdometryRunResult result = run_odometry(*source, config.odometry, out_dir, run_options);
  const double median_ms = result.median_frame_ms();
  std::cout << fmt::format("{} frames, {} registration failures, {} degenerate frames, median {:.1f} ms/frame ({:.1f} Hz)\n",
                           result.frames, result.registration_failures, result.degenerate_frames, median_ms,
                           median_ms > 0 ? 1000.0 / median_ms : 0.0);
  std::cout << result.gravity.describe() << "\n";
  std::cout << fmt::format("wrote {} ({})\n", out_dir.string(), fmt::join(result.files, ", "));
  if (live) live->run_ended(result.interrupted);
  if (result.interrupted) {
    spdlog::warn("interrupted: {} frames written", result.frames);
    return 130;
  }
  return 0;
}

const CommandRegistration kRegistration{Command{
    "odom", "Semantic-assisted LOAM odometry over a sequence folder", 30, [](CLI::App& app) {
      auto options = std::make_shared<OdomOptions>();
      options->source.add_to(app, "Sequence folder (velodyne/, labels/, calib.txt, times.txt)");
      app.add_option("--out", options->out, "Output folder for poses.txt, poses_tum.txt, timing.json")->required();
      app.add_flag("--no-semantics", options->no_semantics,
                   "Label-agnostic run with plain voxel grid (FLOAM-like baseline)");
      add_no_calib_flag(app, options->source.no_calib);
      options->source.add_live_to(app);
      options->serve.add_to(app);
      options->config.add_to(app);
      return [options] { return run_odom(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
