// graph_stats: statistics of per-scan semantic graphs (SGPR, `saloam graph`),
// to compare simulated scans with real KITTI graphs: node count, node class
// mix, node range (horizontal distance from the sensor).
//
//   graph_stats --sequence SEQ [--labels DIR] [--stride 10] [--frames A:B]
//   graph_stats --json graph_0.json graph_3.json ...
//
// Prints one row per source: graphs, mean nodes per graph (min-max), the
// share of each node class among all nodes, and the mean / median node range.

#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "saloam/core/frame_range.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/place/graph_json.hpp"
#include "saloam/place/semantic_graph.hpp"

namespace saloam {
namespace {

struct GraphStats {
  std::size_t graphs = 0, nodes = 0, min_nodes = SIZE_MAX, max_nodes = 0;
  std::array<std::size_t, kNumNodeClasses> per_class{};
  std::vector<double> ranges;

  void add(const SemanticGraph& g) {
    ++graphs;
    nodes += g.size();
    min_nodes = std::min(min_nodes, g.size());
    max_nodes = std::max(max_nodes, g.size());
    for (std::size_t i = 0; i < g.size(); ++i) {
      ++per_class[static_cast<std::size_t>(g.nodes[i])];
      ranges.push_back(g.centers[i].head<2>().norm());
    }
  }
};

void print_header() {
  std::string line = fmt::format("{:<28} {:>6} {:>14}", "source", "graphs", "nodes (range)");
  for (int c = 0; c < kNumNodeClasses; ++c) line += fmt::format(" {:>6.6}", node_class_name(c));
  line += fmt::format(" {:>10} {:>12}", "range mean", "range median");
  std::puts(line.c_str());
}

void print_row(const std::string& name, GraphStats s) {
  if (s.graphs == 0) return;
  std::string line = fmt::format("{:<28} {:>6} {:>5.1f} ({}-{})", name, s.graphs,
                                 static_cast<double>(s.nodes) / static_cast<double>(s.graphs), s.min_nodes, s.max_nodes);
  for (const std::size_t n : s.per_class) line += fmt::format(" {:>5.1f}%", 100.0 * static_cast<double>(n) / static_cast<double>(std::max<std::size_t>(1, s.nodes)));
  double mean = 0;
  for (const double r : s.ranges) mean += r;
  mean /= static_cast<double>(std::max<std::size_t>(1, s.ranges.size()));
  std::nth_element(s.ranges.begin(), s.ranges.begin() + static_cast<std::ptrdiff_t>(s.ranges.size() / 2), s.ranges.end());
  line += fmt::format(" {:>8.1f} m {:>10.1f} m", mean, s.ranges.empty() ? 0.0 : s.ranges[s.ranges.size() / 2]);
  std::puts(line.c_str());
}

int run(int argc, char** argv) {
  CLI::App app{"Statistics of per-scan semantic graphs (node count, class mix, node range)"};
  std::string sequence, labels, frames;
  std::size_t stride = 10;
  std::vector<std::string> json;
  app.add_option("--sequence", sequence, "Sequence folder (velodyne/, labels/)");
  app.add_option("--labels", labels, "Folder of .label files to use instead of labels/");
  app.add_option("--stride", stride, "Every K-th frame")->check(CLI::PositiveNumber);
  app.add_option("--frames", frames, "Frame range A:B");
  app.add_option("--json", json, "SGPR graph files (.json)");
  CLI11_PARSE(app, argc, argv);
  print_header();
  if (!json.empty()) {
    GraphStats all;
    for (const auto& f : json) {
      GraphStats one;
      one.add(read_graph_json(f));
      all.add(read_graph_json(f));
      print_row(std::filesystem::path(f).filename().string(), one);
    }
    if (json.size() > 1) print_row("all json", all);
  }
  if (!sequence.empty()) {
    SequenceOptions options;
    if (!labels.empty()) options.labels_dir = labels;
    const SequenceReader reader(sequence, options);
    const FrameRange range = FrameRange::parse(frames);
    GraphStats stats;
    for (std::size_t i = range.first; i < std::min(range.end, reader.size()); i += stride) {
      stats.add(build_semantic_graph(reader.load_scan(i), GraphBuilderConfig{}));
    }
    print_row(std::filesystem::path(sequence).filename().string(), stats);
  }
  return 0;
}

}  // namespace
}  // namespace saloam

int main(int argc, char** argv) {
  try {
    return saloam::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graph_stats: %s\n", e.what());
    return 1;
  }
}
