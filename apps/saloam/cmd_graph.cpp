// `saloam graph`: the semantic graph of one labelled scan, as SGPR JSON.

#include <iostream>
#include <map>

#include <fmt/format.h>

#include "command.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/place/graph_json.hpp"
#include "saloam/place/semantic_graph.hpp"

namespace saloam::cli {
namespace {

struct GraphArgs {
  std::string sequence;
  std::size_t frame = 0;
  std::string out;
  std::string labels;
  bool no_instances = false;
};

int run_graph(const GraphArgs& args) {
  PathRules().input("sequence", args.sequence).input("--labels", args.labels).output("--out", args.out).check();
  SequenceOptions options;
  if (!args.labels.empty()) options.labels_dir = args.labels;
  const SequenceReader reader(args.sequence, options);
  if (args.frame >= reader.size())
    throw ConfigError(fmt::format("--frame {}: the sequence has {} scans", args.frame, reader.size()));
  if (!reader.has_labels()) throw InputError(args.sequence, "no labels/ folder (give --labels DIR): graphs need semantic labels");
  const LabelledCloud cloud = reader.load_scan(args.frame);

  GraphBuilderConfig config;
  config.use_instances = !args.no_instances;
  const StageTimer timer;
  SemanticGraph graph = build_semantic_graph(cloud, config);
  const double ms = timer.elapsed_ms();
  if (reader.has_poses()) {
    // SGPR stores the KITTI (camera-frame) pose line of the scan.
    const Pose& p = reader.camera_poses().at(args.frame);
    std::array<double, 12> pose{};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) pose[static_cast<std::size_t>(4 * r + c)] = p.matrix()(r, c);
    graph.pose = pose;
  }
  write_graph_json(args.out, graph);

  std::map<int, int> histogram;
  for (const int n : graph.nodes) ++histogram[n];
  std::string classes;
  for (const auto& [c, count] : histogram) classes += fmt::format("{}{} {}", classes.empty() ? "" : ", ", node_class_name(c), count);
  std::cout << fmt::format("frame {} ({} points): {} nodes ({}), {} edges in {:.1f} ms -> {}\n", args.frame, cloud.size(),
                           graph.size(), classes, graph.edges.size(), ms, args.out);
  return 0;
}

const CommandRegistration kRegistration{Command{
    "graph", "Build the semantic graph (SGPR JSON) of one labelled scan", 40, [](CLI::App& app) {
      auto args = std::make_shared<GraphArgs>();
      app.add_option("sequence", args->sequence, "Sequence folder (velodyne/, labels/, poses.txt)")->required();
      app.add_option("--frame", args->frame, "Scan index")->required()->check(non_negative_integer());
      app.add_option("--out", args->out, "Output graph file (.json)")->required();
      app.add_option("--labels", args->labels, "Folder of .label files to use instead of labels/");
      app.add_flag("--no-instances", args->no_instances, "Ignore instance ids: cluster vehicles geometrically too");
      return [args] { return run_graph(*args); };
    }}};

}  // namespace
}  // namespace saloam::cli
