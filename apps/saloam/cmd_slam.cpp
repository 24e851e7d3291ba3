// `saloam slam`: the whole SA-LOAM system (semantic odometry, loop closure,
// pose graph, global semantic map) over a sequence folder. The outputs are
// listed in src/saloam/runs/slam_run.hpp.

#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "live_serving.hpp"
#include "saloam/core/error.hpp"
#include "saloam/eval/evaluation_report.hpp"
#include "saloam/maps/prior_map.hpp"
#include "saloam/runs/output_folder.hpp"
#include "saloam/runs/slam_run.hpp"
#include "saloam/viewer/viewer_page.hpp"

namespace saloam::cli {
namespace {

struct SlamOptions {
  SourceArgs source;
  std::string out;
  std::string detector;
  std::string model;
  bool no_map = false;
  std::string save_map;
  std::string map;
  ServeOptions serve;
  ConfigOptions config;
};

/// `--map`: the map to join, its configuration as the run's (a --config
/// instead, --set on top; the detector must stay the map's). InputError when
/// --save-map is missing or names the map itself (inputs are never replaced).
std::unique_ptr<PriorMap> open_join_map(const SlamOptions& options, SaloamConfig& config) {
  if (options.save_map.empty()) throw InputError(options.map, "--map needs --save-map: the joined map is a new map");
  SavedMap saved = read_map(options.map);
  if (!options.detector.empty()) throw InputError(options.map, "--detector with --map: the map's detector is used");
  config = options.config.resolve_for_map(saved.config);
  return std::make_unique<PriorMap>(
      PriorMap::open(options.map, std::move(saved), static_cast<std::size_t>(config.localize.cached_keyframes)));
}

void print_summary(const SlamRunResult& r) {
  std::cout << fmt::format("{} frames, {} keyframes; {} loops accepted of {} verified; median {:.1f} ms/frame ({:.1f} Hz), "
                           "loop closure {:.2f} ms/frame amortised; peak memory {:.0f} MiB\n",
                           r.frames, r.keyframes, r.loops_accepted, r.loops_verified, r.median_frame_ms,
                           r.median_frame_ms > 0 ? 1000.0 / r.median_frame_ms : 0.0, r.mean_loop_ms, r.peak_rss_mib);
  std::cout << fmt::format("odometry: {} registration failures, {} degenerate frames\n", r.registration_failures,
                           r.degenerate_frames);
  std::cout << r.gravity.describe() << "\n";
  if (r.loop_summary) {
    const auto& s = *r.loop_summary;
    std::cout << fmt::format("loops vs ground truth ({}): {} true, {} false ({} reverse); revisit stretches {} "
                             "({} reverse), missed {} ({} reverse)\n",
                             r.loop_reference, s.accepted_true, s.accepted_false, s.accepted_reverse,
                             s.revisit_stretches, s.reverse_stretches, s.missed_stretches, s.missed_reverse_stretches);
    if (r.loop_summary_poses_txt) {
      std::cout << fmt::format("  against poses.txt (heights as given): {} true, {} false\n",
                               r.loop_summary_poses_txt->accepted_true, r.loop_summary_poses_txt->accepted_false);
    }
  }
  if (r.odometry_evaluation && r.slam_evaluation) {
    std::cout << "| trajectory | KITTI t_err [%] | r_err [deg/100 m] | ATE RMSE [m] |\n|---|---|---|---|\n";
    for (const auto& [name, e] : {std::pair{"odometry", &*r.odometry_evaluation}, std::pair{"loop closed", &*r.slam_evaluation}}) {
      std::cout << fmt::format("| {} | {} | {} | {} |\n", name, format_metric(e->kitti.t_err_percent, 3),
                               format_metric(e->kitti.r_err_deg_per_100m, 3), format_metric(e->ate.aligned.rmse, 3));
    }
  }
}

/// view.html beside the results (as `saloam view OUT_DIR`), added to the
/// summary's files; a warning when it cannot be written.
void write_view_page(OutputFolder& folder) {
  try {
    const ViewerPageStats s = write_viewer_page(folder.path(), folder / "view.html");
    update_run_summary(folder);
    std::cout << fmt::format("3D view: {} ({:.1f} MB, opens in a browser)\n", (folder / "view.html").string(),
                             static_cast<double>(s.bytes) / 1e6);
  } catch (const InputError& e) {
    spdlog::warn("no view.html: {}", e.what());
  }
}

int run_slam_command(const SlamOptions& options) {
  PathRules rules;
  options.source.add_inputs(rules)
      .input("--map", options.map)
      .output("--out", options.out, OutputUse::kFolder)
      .output("--save-map", options.save_map, OutputUse::kReplacedFolder)
      .check();
  SaloamConfig config = options.config.resolve();
  if (!options.detector.empty()) apply_config_option(config, "--detector", "loop.detector", options.detector);
  std::unique_ptr<PriorMap> join_map;
  if (!options.map.empty()) join_map = open_join_map(options, config);
  use_model_option(options.model, config);
  const bool labels = config.odometry.use_semantics || needs_labels(parse_place_detector(config.loop.detector));
  SensorChoice sensor;
  const std::unique_ptr<FrameSource> source = options.source.open(!labels, config, &sensor);
  SlamRunOptions run_options;
  run_options.write_map = !options.no_map;
  if (!options.save_map.empty()) run_options.save_map = options.save_map;
  if (sensor.profile) run_options.sensor = sensor.profile->name;
  run_options.join_map = join_map.get();

  std::unique_ptr<LiveServing> live;  // before the folder: a port in use leaves it untouched
  if (options.serve.serve) {
    live = std::make_unique<LiveServing>(options.source.path, "slam", options.serve.port);
    run_options.follow = live->follower();
  }
  OutputFolder folder = open_slam_folder(options.out, source->info());
  const SlamRunResult result = run_slam(*source, config, load_loop_network(config), folder, run_options);
  print_summary(result);
  if (!result.join.empty()) std::cout << result.join << '\n';
  if (result.map_bytes) {
    std::cout << fmt::format("saved map: {} ({} keyframes, {:.1f} MB, {:.2f} s)\n", options.save_map, result.map_keyframes,
                             static_cast<double>(*result.map_bytes) / 1e6, result.map_save_seconds);
  }
  if (run_options.write_map && !result.interrupted) write_view_page(folder);
  std::cout << fmt::format("wrote {} ({})\n", folder.path().string(), fmt::join(folder.files(), ", "));
  if (live) live->run_ended(result.interrupted);
  if (result.interrupted) {
    spdlog::warn("interrupted: results of the {} frames processed were written", result.frames);
    return 130;
  }
  return 0;
}

const CommandRegistration kRegistration{Command{
    "slam", "SA-LOAM SLAM: semantic odometry with loop closure, pose graph and global semantic map", 25,
    [](CLI::App& app) {
      auto options = std::make_shared<SlamOptions>();
      options->source.add_to(app, "Sequence folder (velodyne/, labels/, calib.txt, times.txt)");
      app.add_option("--out", options->out, "Output folder")->required();
      app.add_option("--detector", options->detector, "Loop detector: scancontext, sgpr, hybrid or ssc (loop.detector)")
          ->check(CLI::IsMember({"scancontext", "sgpr", "hybrid", "ssc"}));
      app.add_option("--model", options->model, "SGPR weights (.sgw) for the sgpr and hybrid detectors (loop.sgpr_model)")
          ->check(CLI::ExistingFile);
      app.add_flag("--no-map", options->no_map, "Skip the global map (map.ply, map.png)");
      app.add_option("--save-map", options->save_map,
                     "Save the map for later runs (a folder: keyframes, descriptors, pose graph, configuration; "
                     "docs/map_format.md); `saloam localize --map` reads it");
      app.add_option("--map", options->map,
                     "Join this saved map (multi-session SLAM): cross-session loop closure against its keyframes and "
                     "one pose graph over both; needs --save-map (the joined map; the map given is not changed) and "
                     "runs with the map's configuration")
          ->check(CLI::ExistingDirectory);
      add_no_calib_flag(app, options->source.no_calib);
      options->source.add_live_to(app);
      options->serve.add_to(app);
      options->config.add_to(app);
      return [options] { return run_slam_command(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
