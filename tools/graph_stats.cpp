// graph_stats: statistics of per-scan semantic graphs (SGPR, `saloam graph`),
// to compare simulated scans with real KITTI graphs: node count, node class
// mix, node range (horizontal distance from the sensor).
//
//   graph_stats --sequence SEQ [--labels DIR] [--stride 10] [--frames A:B]
//   graph_stats --json graph_0.json graph_3.json ...
//
// Prints one row per source: graphs, mean nodes per graph (min-max), the
// share of each node class among all nodes, and the mean / median node range.
//
// With --sequence and poses, also the graphs' repeatability on revisits: for
// every pair of graphs at most --revisit-distance apart (3 m, SGPR's
// positives) and at least --exclude-recent frames apart in the sequence, the
// share of one graph's nodes that have a node of the same class within
// --match-radius in the other, after moving it with the true relative pose.
// A place recognizer on graphs can only match what repeats.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "saloam/core/frame_range.hpp"
#include "saloam/core/types.hpp"
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

struct RepeatabilityOptions {
  double revisit_distance = 3.0;   ///< [m] graphs this close are one place (SGPR's positives)
  std::size_t exclude_recent = 50;  ///< frames: nearer pairs are the same pass, not a revisit
  double match_radius = 2.0;        ///< [m] a node repeats when the other graph has one of its class this close
};

/// Share of `a`'s nodes with a same-class node of `b` within `radius`, b's
/// centres moved into a's frame by `a_from_b`.
double repeated_share(const SemanticGraph& a, const SemanticGraph& b, const Pose& a_from_b, double radius,
                      std::array<std::size_t, kNumNodeClasses>& seen, std::array<std::size_t, kNumNodeClasses>& repeated) {
  if (a.size() == 0) return 0.0;
  std::size_t hits = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto c = static_cast<std::size_t>(a.nodes[i]);
    ++seen[c];
    for (std::size_t j = 0; j < b.size(); ++j) {
      if (b.nodes[j] == a.nodes[i] && (a_from_b * b.centers[j] - a.centers[i]).norm() <= radius) {
        ++hits;
        ++repeated[c];
        break;
      }
    }
  }
  return static_cast<double>(hits) / static_cast<double>(a.size());
}

void print_repeatability(const std::vector<std::size_t>& frames, const std::vector<SemanticGraph>& graphs,
                         const std::vector<Pose>& lidar_poses, const RepeatabilityOptions& options) {
  std::vector<double> shares;
  std::array<std::size_t, kNumNodeClasses> seen{}, repeated{};
  for (std::size_t a = 0; a < graphs.size(); ++a) {
    for (std::size_t b = a + 1; b < graphs.size(); ++b) {
      if (frames[b] - frames[a] < options.exclude_recent) continue;
      const Pose& pa = lidar_poses[frames[a]];
      const Pose& pb = lidar_poses[frames[b]];
      if ((pa.translation() - pb.translation()).norm() > options.revisit_distance) continue;
      const Pose a_from_b = pa.inverse() * pb;
      // Both directions: each graph's nodes looked up in the other.
      shares.push_back(repeated_share(graphs[a], graphs[b], a_from_b, options.match_radius, seen, repeated));
      shares.push_back(repeated_share(graphs[b], graphs[a], a_from_b.inverse(), options.match_radius, seen, repeated));
    }
  }
  if (shares.empty()) {
    std::puts("repeatability: no revisits (no two graphs within the revisit distance)");
    return;
  }
  double mean = 0;
  for (const double v : shares) mean += v;
  mean /= static_cast<double>(shares.size());
  std::sort(shares.begin(), shares.end());
  std::puts(fmt::format("repeatability over {} revisit pairs ({:.0f} m, >= {} frames apart): nodes with a same-class "
                        "node within {:.1f} m in the other graph, median {:.2f}, mean {:.2f}, 10th percentile {:.2f}",
                        shares.size() / 2, options.revisit_distance, options.exclude_recent, options.match_radius,
                        shares[shares.size() / 2], mean, shares[shares.size() / 10])
                .c_str());
  std::string line = "  per class:";
  for (int c = 0; c < kNumNodeClasses; ++c) {
    const auto uc = static_cast<std::size_t>(c);
    if (seen[uc] == 0) continue;
    line += fmt::format(" {} {:.2f} ({})", node_class_name(c),
                        static_cast<double>(repeated[uc]) / static_cast<double>(seen[uc]), seen[uc]);
  }
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
  RepeatabilityOptions repeat;
  bool repeatability = false;
  app.add_flag("--repeatability", repeatability, "With --sequence: how much of a graph repeats on revisits (needs poses.txt)");
  app.add_option("--revisit-distance", repeat.revisit_distance, "[m] revisits are graphs this close (default 3)")
      ->check(CLI::PositiveNumber);
  app.add_option("--exclude-recent", repeat.exclude_recent, "Pairs fewer frames apart are not revisits (default 50)");
  app.add_option("--match-radius", repeat.match_radius, "[m] a node repeats with a same-class node this close (default 2)")
      ->check(CLI::PositiveNumber);
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
    if (repeatability && !reader.has_poses()) throw std::runtime_error(sequence + ": --repeatability needs poses.txt");
    GraphStats stats;
    std::vector<std::size_t> frames;
    std::vector<SemanticGraph> graphs;
    for (std::size_t i = range.first; i < std::min(range.end, reader.size()); i += stride) {
      graphs.push_back(build_semantic_graph(reader.load_scan(i), GraphBuilderConfig{}));
      frames.push_back(i);
      stats.add(graphs.back());
    }
    print_row(std::filesystem::path(sequence).filename().string(), stats);
    if (repeatability) print_repeatability(frames, graphs, reader.lidar_poses(), repeat);
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
