#pragma once
// The pose graph of the SLAM back end (paper Sec. III-C, "Pose Graph
// Optimization"), solved with Ceres (the paper used g2o). Nodes are keyframe
// poses T_i = T_world<-sensor_i; an edge (i, j) measures Z_ij ~ T_i^-1 T_j
// and has the error of the paper's equation
//     e_ij = Z_ij^-1 (T_i^-1 T_j)  ->  [ R_Z^T (t_ij - t_Z) ; Log(R_Z^T R_ij) ]  (translation [m], rotation [rad]),
// the tangent vector of the right perturbation T_j = T_i Z_ij exp(e), whitened
// by the square root of the edge's information. Odometry edges join
// consecutive keyframes; loop edges come from geometric verification. The
// first node is fixed (it defines the world frame).
//
// Loop edges are robust in a second phase: a correct loop after hundreds of
// metres of drift starts with an error of hundreds of standard deviations,
// where a robust loss would already have silenced it. So each optimisation
// first solves plain least squares (the verified loops pull the trajectory
// into shape), then again with a Cauchy loss on the loop edges: a loop that
// disagrees with the others keeps a large error there and loses its weight. Each pose is a unit
// quaternion on Ceres' quaternion manifold plus a translation.

#include <cstddef>
#include <deque>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"

namespace ceres {
class Problem;
class LossFunctionWrapper;
}

namespace saloam {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// Whitened error of one edge (the Ceres cost function), templated for
/// automatic differentiation. Parameters: t_i (3), q_i (4, x y z w), t_j, q_j.
struct RelativePoseError {
  RelativePoseError(const Pose& measured, const Matrix6d& sqrt_information)
      : t_measured(measured.translation()),
        q_measured(Eigen::Quaterniond(measured.rotation()).normalized()),
        sqrt_information(sqrt_information) {}

  template <class T>
  bool operator()(const T* t_i, const T* q_i, const T* t_j, const T* q_j, T* residual) const;

  Eigen::Vector3d t_measured;
  Eigen::Quaterniond q_measured;
  Matrix6d sqrt_information;
};

enum class EdgeKind { kOdometry, kLoop };

struct PoseGraphEdge {
  std::size_t from = 0, to = 0;
  Pose measured = Pose::Identity();  ///< Z_ij = T_from^-1 T_to as measured
  Matrix6d information = Matrix6d::Identity();
  EdgeKind kind = EdgeKind::kOdometry;
};

/// Built from the configuration (slam.*), which holds the defaults.
struct PoseGraphOptions {
  int max_iterations{};        ///< Levenberg-Marquardt iterations per phase
  double loop_robust_scale{};  ///< Cauchy scale of loop edges (whitened units)

  static PoseGraphOptions from_config(const SlamConfig& config);
};

struct PoseGraphSummary {
  bool usable = false;        ///< Ceres returned a usable solution
  int iterations = 0;         ///< both phases
  double initial_cost = 0, final_cost = 0;
  double seconds = 0;
};

class PoseGraph {
 public:
  PoseGraph();
  ~PoseGraph();
  PoseGraph(const PoseGraph&) = delete;
  PoseGraph& operator=(const PoseGraph&) = delete;

  /// Adds a node with its initial estimate; returns its index. The first node is held fixed.
  std::size_t add_node(const Pose& initial);
  /// Adds an edge; both nodes must exist and differ (std::invalid_argument otherwise).
  /// The information must be symmetric positive definite.
  void add_edge(const PoseGraphEdge& edge);

  /// Optimises every pose (Levenberg-Marquardt, sparse Cholesky) from the
  /// current estimates: plain least squares, then robust loop edges.
  PoseGraphSummary optimize(const PoseGraphOptions& options);

  /// Current estimate of node i (rotation re-orthonormalised).
  [[nodiscard]] Pose pose(std::size_t i) const;
  /// Overwrites the estimate of a node (e.g. to carry a correction forward to a new node).
  void set_pose(std::size_t i, const Pose& pose);
  [[nodiscard]] std::size_t size() const { return nodes_.size(); }
  [[nodiscard]] const std::vector<PoseGraphEdge>& edges() const { return edges_; }
  /// The edge's whitened error at the current estimates (length 6).
  [[nodiscard]] Eigen::Matrix<double, 6, 1> edge_error(std::size_t edge) const;

 private:
  struct Node {
    double t[3];
    double q[4];  ///< x y z w (Eigen's storage order)
  };
  std::deque<Node> nodes_;  ///< stable addresses: Ceres keeps pointers to them
  std::vector<PoseGraphEdge> edges_;
  std::vector<ceres::LossFunctionWrapper*> loop_losses_;  ///< owned by problem_
  std::unique_ptr<ceres::Problem> problem_;
};

/// Square root (upper Cholesky factor L^T with L L^T = information) used to whiten an edge.
Matrix6d information_sqrt(const Matrix6d& information);

// ---- implementation of the templated error ----

template <class T>
bool RelativePoseError::operator()(const T* t_i_ptr, const T* q_i_ptr, const T* t_j_ptr, const T* q_j_ptr,
                                   T* residual_ptr) const {
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_i(t_i_ptr), t_j(t_j_ptr);
  const Eigen::Map<const Eigen::Quaternion<T>> q_i(q_i_ptr), q_j(q_j_ptr);
  // Estimated relative pose T_i^-1 T_j.
  const Eigen::Quaternion<T> q_i_inverse = q_i.conjugate();
  const Eigen::Quaternion<T> q_ij = q_i_inverse * q_j;
  const Eigen::Matrix<T, 3, 1> t_ij = q_i_inverse * (t_j - t_i);
  // Z^-1 (T_i^-1 T_j).
  const Eigen::Quaternion<T> q_z_inverse = q_measured.conjugate().template cast<T>();
  Eigen::Quaternion<T> q_error = q_z_inverse * q_ij;
  const Eigen::Matrix<T, 3, 1> t_error = q_z_inverse * (t_ij - t_measured.template cast<T>());
  // Rotation error as the rotation vector Log(q_error), sign-fixed so that w >= 0.
  if (q_error.w() < T(0)) q_error.coeffs() = -q_error.coeffs();
  const T sin_half = q_error.vec().norm();
  Eigen::Matrix<T, 3, 1> r_error;
  if (sin_half > T(1e-9)) {
    const T angle = T(2) * atan2(sin_half, q_error.w());
    r_error = q_error.vec() * (angle / sin_half);
  } else {
    r_error = T(2) * q_error.vec();  // first-order: Log(q) = 2 v for small rotations
  }
  Eigen::Matrix<T, 6, 1> error;
  error << t_error, r_error;
  Eigen::Map<Eigen::Matrix<T, 6, 1>> residual(residual_ptr);
  residual = sqrt_information.template cast<T>() * error;
  return true;
}

}  // namespace saloam
