// `saloam localize`: localisation in a map saved by `saloam slam --save-map`
// (relocalisation without an initial guess, tracking against the map with
// the odometry between). The outputs are listed in src/saloam/runs/localize_run.hpp.

#include <iostream>
#include <memory>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "live_serving.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/maps/prior_map.hpp"
#include "saloam/runs/localize_run.hpp"
#include "saloam/runs/session_eval.hpp"
#include "saloam/runs/slam_run.hpp"

namespace saloam::cli {
namespace {

struct LocalizeOptions {
  SourceArgs source;
  std::string map;
  std::string out;
  std::string model;
  ServeOptions serve;
  ConfigOptions config;
};

/// T_map<-L0 when the map and the scans are passes of one simulated world
/// (`simulate --passes`), both from their first frame: the truth to judge
/// relocalisations by.
std::optional<Pose> simulated_truth(const PriorMap& map, const SourceInfo& info) {
  const MapManifest& m = map.saved().manifest;
  if (m.source.empty() || !info.folder || m.first_frame != 0 || info.first_frame != 0) return std::nullopt;
  const auto map_pass = read_simulated_pass(m.source), run_pass = read_simulated_pass(*info.folder);
  if (!map_pass || !run_pass || map_pass->passes != run_pass->passes) return std::nullopt;
  return orthonormalized(map_pass->origin.inverse() * run_pass->origin);
}

/// What the run did: how the frames were placed, when it relocalised, and
/// its errors against the truth when known.
void print_summary(const LocalizeRunResult& r) {
  std::cout << fmt::format("{} frames: {} localized, {} on the odometry outside the map, {} not placed; median {:.1f} ms/frame "
                           "({:.1f} Hz); peak memory {:.0f} MiB; {} map keyframes read\n",
                           r.frames, r.localized, r.odometry, r.unplaced, r.median_frame_ms,
                           r.median_frame_ms > 0 ? 1000.0 / r.median_frame_ms : 0.0, r.peak_rss_mib, r.map_loads);
  if (r.first_placed_m) {
    std::cout << fmt::format("relocalised after {:.1f} m (frame {}); {} hypotheses, {} refuted; left the map {} times, "
                             "came back {} times\n",
                             *r.first_placed_m, r.first_placed_frame.value_or(0), r.hypotheses + r.confirmed, r.refuted,
                             r.left_map, r.reentered);
  } else {
    std::cout << "never relocalised: no frame was placed in the map\n";
  }
  if (r.false_relocalizations) {
    std::cout << fmt::format("against the truth in the map frame: {} false relocalisations; localized frames RMSE {} m (max {} m), "
                             "all placed frames RMSE {} m\n",
                             *r.false_relocalizations, r.localized_rmse_m ? fmt::format("{:.3f}", *r.localized_rmse_m) : "-",
                             r.localized_max_m ? fmt::format("{:.3f}", *r.localized_max_m) : "-",
                             r.placed_rmse_m ? fmt::format("{:.3f}", *r.placed_rmse_m) : "-");
  }
  if (r.map_error_where_localized_m) {
    std::cout << fmt::format("the map's own error where the frames were localized: RMSE {:.3f} m (the localized frames "
                             "inherit it)\n", *r.map_error_where_localized_m);
  }
  if (r.aligned_ate_m) std::cout << fmt::format("placed frames against the reference: ATE {:.3f} m (SE(3)-aligned)\n", *r.aligned_ate_m);
}

int run_localize_command(const LocalizeOptions& options) {
  PathRules rules;
  options.source.add_inputs(rules).input("--map", options.map).output("--out", options.out, OutputUse::kFolder).check();
  const StageTimer load_timer;
  // The map's own configuration (its detector made the descriptors), a
  // --config instead, then --set on top.
  SavedMap saved = read_map(options.map);
  SaloamConfig config = options.config.resolve_for_map(saved.config);
  use_model_option(options.model, config);
  const PriorMap map =
      PriorMap::open(options.map, std::move(saved), static_cast<std::size_t>(config.localize.cached_keyframes));
  const double load_s = load_timer.elapsed_s();
  std::cout << fmt::format("map {}: {} keyframes, {} edges ({} loops), detector {}, loaded in {:.2f} s (features on demand)\n",
                           options.map, map.size(), map.saved().edges.size(), map.saved().manifest.loop_edges,
                           config.loop.detector, load_s);

  const bool labels = config.odometry.use_semantics || needs_labels(parse_place_detector(config.loop.detector));
  const std::unique_ptr<FrameSource> source = options.source.open(!labels, config);
  LocalizeRunOptions run_options;
  run_options.truth_map_from_source = simulated_truth(map, source->info());
  if (run_options.truth_map_from_source) {
    run_options.map_error = map_error_against_source(map);
    std::cout << "the map and the scans are passes of one simulated world: relocalisations are judged against the truth\n";
  }
  std::unique_ptr<LiveServing> live;
  if (options.serve.serve) {
    live = std::make_unique<LiveServing>(options.source.path, "localize", options.serve.port);
    live->show_map(options.map);
    run_options.follow = live->follower();
  }
  const LocalizeRunResult r = run_localize(*source, config, map, load_loop_network(config), options.out, run_options);

  print_summary(r);
  std::cout << fmt::format("wrote {} ({})\n", options.out, fmt::join(r.files, ", "));
  if (live) live->run_ended(r.interrupted);
  if (r.interrupted) {
    spdlog::warn("interrupted: results of the {} frames processed were written", r.frames);
    return 130;
  }
  return 0;
}

const CommandRegistration kRegistration{Command{
    "localize", "Localise a run in a saved map (slam --save-map): relocalisation, then tracking against the map", 26,
    [](CLI::App& app) {
      auto options = std::make_shared<LocalizeOptions>();
      options->source.add_to(app, "Scans to localise (any layout saloam reads)");
      app.add_option("--map", options->map, "Map folder written by `saloam slam --save-map`")->required();
      app.add_option("--out", options->out, "Output folder")->required();
      app.add_option("--model", options->model, "SGPR weights (.sgw) when the map's detector uses SGPR")
          ->check(CLI::ExistingFile);
      add_no_calib_flag(app, options->source.no_calib);
      options->source.add_live_to(app);
      options->serve.add_to(app);
      options->config.add_to(app);
      return [options] { return run_localize_command(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
