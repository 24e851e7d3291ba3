// loop_closure_oracle: the lowest absolute trajectory error that loop closure
// can reach on a sequence, given its odometry. Builds the pose graph of
// `saloam slam` (odometry edges between nodes every --step frames) and adds a
// loop edge carrying the exact ground-truth relative pose at every node that
// revisits an earlier one (within --radius metres, after --exclude metres of
// travel), then optimises and reports the ATE before and after. A real loop
// detector finds a subset of these loops, with errors: its ATE can at best
// approach this bound, which depends on where the sequence revisits itself.
//
//   loop_closure_oracle --gt SEQ/poses.txt --odometry OUT/poses_odometry.txt [--radius 5] [--step 5]
//
// Both files in KITTI format and the same frame (e.g. camera frame, as
// `saloam slam` writes them); the odometry's information is a fixed
// 1 cm / 0.06 deg standard deviation per edge.

#include <cstdio>
#include <exception>
#include <optional>
#include <stdexcept>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "saloam/eval/trajectory_metrics.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/slam/pose_graph.hpp"

namespace saloam {
namespace {

struct OracleOptions {
  std::string gt, odometry;
  double radius = 5.0;
  double exclude = 50.0;
  std::size_t step = 5;
};

std::vector<double> travelled(const std::vector<Pose>& poses) {
  std::vector<double> d(poses.size(), 0.0);
  for (std::size_t i = 1; i < poses.size(); ++i) {
    d[i] = d[i - 1] + (poses[i].translation() - poses[i - 1].translation()).norm();
  }
  return d;
}

int run(const OracleOptions& o) {
  const std::vector<Pose> gt = read_kitti_poses(o.gt), odometry = read_kitti_poses(o.odometry);
  if (gt.size() != odometry.size()) {
    throw std::runtime_error(fmt::format("{} ground-truth poses but {} odometry poses", gt.size(), odometry.size()));
  }
  std::vector<std::size_t> frames;
  for (std::size_t i = 0; i < odometry.size(); i += o.step) frames.push_back(i);

  Matrix6d information = Matrix6d::Identity();
  information.diagonal() << 1e4, 1e4, 1e4, 1e6, 1e6, 1e6;
  PoseGraph graph;
  graph.add_node(odometry[0]);
  for (std::size_t k = 1; k < frames.size(); ++k) {
    graph.add_node(odometry[frames[k]]);
    graph.add_edge({k - 1, k, odometry[frames[k - 1]].inverse() * odometry[frames[k]], information, EdgeKind::kOdometry});
  }
  const std::vector<double> distance = travelled(gt);
  std::size_t loops = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const std::size_t i = frames[k];
    double best = o.radius;
    std::optional<std::size_t> match;
    for (std::size_t m = 0; m < k && distance[i] - distance[frames[m]] > o.exclude; ++m) {
      const double d = (gt[i].translation() - gt[frames[m]].translation()).norm();
      if (d < best) {
        best = d;
        match = m;
      }
    }
    if (!match) continue;
    graph.add_edge({*match, k, gt[frames[*match]].inverse() * gt[i], information, EdgeKind::kLoop});
    ++loops;
  }
  PoseGraphOptions options = PoseGraphOptions::from_config(SlamConfig{});
  options.max_iterations = 50;
  const PoseGraphSummary summary = graph.optimize(options);

  std::vector<Pose> truth, before, after;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    truth.push_back(gt[frames[k]]);
    before.push_back(odometry[frames[k]]);
    after.push_back(graph.pose(k));
  }
  const double ate_before = compute_ate(truth, before).aligned.rmse, ate_after = compute_ate(truth, after).aligned.rmse;
  fmt::print("{} nodes, {} exact loop edges (radius {} m){}\n", frames.size(), loops, o.radius,
             summary.usable ? "" : "; the optimisation did not converge");
  fmt::print("ATE RMSE (se3-aligned, nodes only): odometry {:.3f} m, with every loop closed exactly {:.3f} m ({:+.0f} %)\n",
             ate_before, ate_after, 100.0 * (ate_after / ate_before - 1.0));
  return 0;
}

}  // namespace
}  // namespace saloam

int main(int argc, char** argv) {
  CLI::App app{"The ATE that exact loop closures at every revisit would give (a bound for loop closure)"};
  saloam::OracleOptions options;
  app.add_option("--gt", options.gt, "Ground-truth poses (KITTI format)")->required()->check(CLI::ExistingFile);
  app.add_option("--odometry", options.odometry, "Odometry poses (KITTI format, same frame)")->required()->check(CLI::ExistingFile);
  app.add_option("--radius", options.radius, "A node within this distance [m] of an earlier one revisits it")->check(CLI::PositiveNumber);
  app.add_option("--exclude", options.exclude, "Only nodes at least this far back along the path [m]")->check(CLI::NonNegativeNumber);
  app.add_option("--step", options.step, "Frames between graph nodes")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  try {
    return saloam::run(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
