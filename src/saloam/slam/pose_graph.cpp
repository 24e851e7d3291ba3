#include "saloam/slam/pose_graph.hpp"

#include <stdexcept>

#include <ceres/ceres.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "saloam/core/lie.hpp"
#include "saloam/core/profiling.hpp"

namespace saloam {

Matrix6d information_sqrt(const Matrix6d& information) {
  const Matrix6d symmetric = 0.5 * (information + information.transpose());
  const Eigen::LLT<Matrix6d> llt(symmetric);
  if (llt.info() != Eigen::Success) {
    throw std::invalid_argument("pose graph: edge information is not positive definite");
  }
  return llt.matrixU();
}

PoseGraph::PoseGraph() {
  ceres::Problem::Options options;
  options.manifold_ownership = ceres::TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  problem_ = std::make_unique<ceres::Problem>(options);
}

PoseGraph::~PoseGraph() = default;

std::size_t PoseGraph::add_node(const Pose& initial) {
  nodes_.emplace_back();
  set_pose(nodes_.size() - 1, initial);
  Node& node = nodes_.back();
  problem_->AddParameterBlock(node.t, 3);
  problem_->AddParameterBlock(node.q, 4, new ceres::EigenQuaternionManifold);
  if (nodes_.size() == 1) {
    problem_->SetParameterBlockConstant(node.t);
    problem_->SetParameterBlockConstant(node.q);
  }
  return nodes_.size() - 1;
}

void PoseGraph::add_edge(const PoseGraphEdge& edge) {
  if (edge.from >= nodes_.size() || edge.to >= nodes_.size() || edge.from == edge.to) {
    throw std::invalid_argument("pose graph: an edge must join two different existing nodes");
  }
  auto* cost = new ceres::AutoDiffCostFunction<RelativePoseError, 6, 3, 4, 3, 4>(
      new RelativePoseError(edge.measured, information_sqrt(edge.information)));
  ceres::LossFunctionWrapper* loss = nullptr;
  if (edge.kind == EdgeKind::kLoop) {
    loss = new ceres::LossFunctionWrapper(nullptr, ceres::TAKE_OWNERSHIP);  // plain until optimize() says otherwise
    loop_losses_.push_back(loss);
  }
  Node& a = nodes_[edge.from];
  Node& b = nodes_[edge.to];
  problem_->AddResidualBlock(cost, loss, a.t, a.q, b.t, b.q);
  edges_.push_back(edge);
}

PoseGraphOptions PoseGraphOptions::from_config(const SlamConfig& config) {
  return {config.max_iterations, config.loop_robust_scale};
}

PoseGraphSummary PoseGraph::optimize(const PoseGraphOptions& options) {
  PoseGraphSummary summary;
  if (nodes_.size() < 2 || edges_.empty()) {
    summary.usable = true;
    return summary;
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;  // deterministic and within the one-core budget
  solver.logging_type = ceres::SILENT;
  solver.minimizer_progress_to_stdout = false;
  const StageTimer timer;
  summary.usable = true;
  for (const bool robust : {false, true}) {
    for (auto* loss : loop_losses_) {
      loss->Reset(robust ? new ceres::CauchyLoss(options.loop_robust_scale) : nullptr, ceres::TAKE_OWNERSHIP);
    }
    ceres::Solver::Summary result;
    ceres::Solve(solver, problem_.get(), &result);
    summary.usable = summary.usable && result.IsSolutionUsable();
    summary.iterations += static_cast<int>(result.iterations.size());
    if (!robust) summary.initial_cost = result.initial_cost;
    summary.final_cost = result.final_cost;
  }
  summary.seconds = timer.elapsed_s();
  for (auto& node : nodes_) {  // back onto the unit sphere exactly
    Eigen::Map<Eigen::Quaterniond> q(node.q);
    q.normalize();
  }
  return summary;
}

Pose PoseGraph::pose(std::size_t i) const {
  const Node& node = nodes_.at(i);
  Pose T = Pose::Identity();
  T.linear() = Eigen::Quaterniond(node.q[3], node.q[0], node.q[1], node.q[2]).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(node.t[0], node.t[1], node.t[2]);
  return T;
}

void PoseGraph::set_pose(std::size_t i, const Pose& pose) {
  Node& node = nodes_.at(i);
  const Eigen::Quaterniond q(orthonormalize(pose.rotation()));
  node.q[0] = q.x();
  node.q[1] = q.y();
  node.q[2] = q.z();
  node.q[3] = q.w();
  for (int k = 0; k < 3; ++k) node.t[k] = pose.translation()[k];
}

Eigen::Matrix<double, 6, 1> PoseGraph::edge_error(std::size_t e) const {
  const PoseGraphEdge& edge = edges_.at(e);
  const RelativePoseError error(edge.measured, information_sqrt(edge.information));
  const Node& a = nodes_[edge.from];
  const Node& b = nodes_[edge.to];
  Eigen::Matrix<double, 6, 1> r;
  error(a.t, a.q, b.t, b.q, r.data());
  return r;
}

}  // namespace saloam
