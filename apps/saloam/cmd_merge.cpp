// `saloam merge`: two saved maps joined into one offline (cross-session loop
// closure between their keyframes and one pose graph, in MAP_A's frame;
// maps/session_join.hpp, docs/map_format.md).

#include <iostream>
#include <memory>

#include <fmt/format.h>

#include "command.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/path_rules.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/maps/map_format.hpp"
#include "saloam/maps/prior_map.hpp"
#include "saloam/maps/session_join.hpp"
#include "saloam/maps/session_report.hpp"
#include "saloam/runs/slam_run.hpp"

namespace saloam::cli {
namespace {

struct MergeOptions {
  std::string map_a, map_b, out, model;
  ConfigOptions config;
};

int run_merge_command(const MergeOptions& options) {
  PathRules()
      .input("MAP_A", options.map_a)
      .input("MAP_B", options.map_b)
      .output("--out", options.out, OutputUse::kReplacedFolder)
      .check();
  const StageTimer timer;
  SavedMap a = read_map(options.map_a);
  SaloamConfig config = options.config.resolve_for_map(a.config);
  use_model_option(options.model, config);
  const auto cached = static_cast<std::size_t>(config.localize.cached_keyframes);
  const PriorMap base = PriorMap::open(options.map_a, std::move(a), cached);
  const PriorMap joining = PriorMap::open(options.map_b, cached);
  check_map_destination(options.out);
  const PlaceRecognizer places = PlaceRecognizer::from_config(config.loop, load_loop_network(config));
  const JoinedMaps joined = join_maps(base, joining, config, places);
  write_joined_map(options.out, joined, base, joining);
  std::cout << fmt::format("{} ({} keyframes) + {} ({} keyframes) -> {}: {} sessions, {} cross-session loop edges, "
                           "{} fits verified; {:.1f} MB, {:.1f} s\n",
                           options.map_a, base.size(), options.map_b, joining.size(), options.out,
                           joined.map.manifest.sessions.size(), joined.cross_session_loops, joined.records.size(),
                           static_cast<double>(map_disk_bytes(options.out)) / 1e6, timer.elapsed_s());
  std::cout << describe_join(joined, options.map_a) << '\n';
  return 0;
}

const CommandRegistration kRegistration{Command{
    "merge", "Merge two saved maps into one (cross-session loop closure, one pose graph, MAP_A's frame)", 28,
    [](CLI::App& app) {
      auto options = std::make_shared<MergeOptions>();
      app.add_option("MAP_A", options->map_a, "The base map (its frame is the merged map's)")
          ->required()->check(CLI::ExistingDirectory);
      app.add_option("MAP_B", options->map_b, "The map joined to it")->required()->check(CLI::ExistingDirectory);
      app.add_option("--out", options->out, "The merged map's folder (a new map; the inputs are not changed)")->required();
      app.add_option("--model", options->model, "SGPR weights (.sgw) when the maps' detector uses SGPR")
          ->check(CLI::ExistingFile);
      options->config.add_to(app);
      return [options] { return run_merge_command(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
