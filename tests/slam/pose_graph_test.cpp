// The pose graph: its error function against the paper's equation and
// against numeric differentiation, and optimisations with known answers.

#include <cmath>

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include "saloam/core/lie.hpp"
#include "saloam/slam/pose_graph.hpp"

namespace saloam {
namespace {

Pose make_pose(double x, double y, double z, double roll, double pitch, double yaw) {
  Pose T = Pose::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

struct Params {
  double t[3];
  double q[4];
  explicit Params(const Pose& T) {
    const Eigen::Quaterniond quat(T.rotation());
    q[0] = quat.x(), q[1] = quat.y(), q[2] = quat.z(), q[3] = quat.w();
    for (int k = 0; k < 3; ++k) t[k] = T.translation()[k];
  }
};

TEST(RelativePoseError, IsTheTangentOfZInverseTimesRelative) {
  const Pose Ti = make_pose(1, 2, 0.5, 0.1, -0.05, 0.7);
  const Pose Z = make_pose(3, -1, 0.2, 0.02, 0.03, -0.4);
  const Vector6d e_true = (Vector6d() << 0.05, -0.02, 0.01, 0.004, -0.003, 0.02).finished();
  const Pose Tj = Ti * Z * se3_exp(e_true);  // T_j = T_i Z exp(e)
  const Params a(Ti), b(Tj);
  const RelativePoseError error(Z, Matrix6d::Identity());
  Vector6d r;
  ASSERT_TRUE(error(a.t, a.q, b.t, b.q, r.data()));
  // e = [R_Z^T (t_ij - t_Z); Log(R_Z^T R_ij)] = [translation of exp(e); phi].
  const Pose E = Z.inverse() * (Ti.inverse() * Tj);
  EXPECT_TRUE(r.head<3>().isApprox(E.translation(), 1e-9));
  EXPECT_TRUE(r.tail<3>().isApprox(so3_log(E.rotation()), 1e-9));
  EXPECT_TRUE(r.tail<3>().isApprox(e_true.tail<3>(), 1e-9));
  // Whitening: r = sqrt(information) * e.
  Matrix6d info = Matrix6d::Identity();
  info.diagonal() << 4, 4, 4, 100, 100, 100;
  const RelativePoseError weighted(Z, information_sqrt(info));
  Vector6d rw;
  weighted(a.t, a.q, b.t, b.q, rw.data());
  EXPECT_NEAR(rw.squaredNorm(), r.transpose() * info * r, 1e-12);
  // A perfect measurement has zero error.
  const RelativePoseError exact(Ti.inverse() * Tj, Matrix6d::Identity());
  exact(a.t, a.q, b.t, b.q, r.data());
  EXPECT_LT(r.norm(), 1e-12);
}

TEST(RelativePoseError, AutomaticJacobianMatchesNumericDifferentiation) {
  const Pose Ti = make_pose(-4, 1, 0.3, 0.05, 0.1, 2.5);
  const Pose Tj = make_pose(6, 8, -0.2, -0.1, 0.02, -2.9);  // across the +-pi yaw seam
  const Pose Z = make_pose(9, 3, 0.1, 0.03, -0.02, 1.1);
  Matrix6d info = Matrix6d::Identity() * 3.0;
  info(0, 3) = info(3, 0) = 0.5;
  info(4, 4) = 50;
  const Matrix6d sqrt_info = information_sqrt(info);
  ceres::AutoDiffCostFunction<RelativePoseError, 6, 3, 4, 3, 4> automatic(new RelativePoseError(Z, sqrt_info));
  ceres::NumericDiffCostFunction<RelativePoseError, ceres::CENTRAL, 6, 3, 4, 3, 4> numeric(
      new RelativePoseError(Z, sqrt_info));
  const Params a(Ti), b(Tj);
  const double* parameters[] = {a.t, a.q, b.t, b.q};
  const int sizes[] = {3, 4, 3, 4};
  double r_auto[6], r_num[6];
  std::vector<std::vector<double>> j_auto(4), j_num(4);
  double* ja[4];
  double* jn[4];
  for (int k = 0; k < 4; ++k) {
    j_auto[k].resize(6 * sizes[k]);
    j_num[k].resize(6 * sizes[k]);
    ja[k] = j_auto[k].data();
    jn[k] = j_num[k].data();
  }
  ASSERT_TRUE(automatic.Evaluate(parameters, r_auto, ja));
  ASSERT_TRUE(numeric.Evaluate(parameters, r_num, jn));
  for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(r_auto[i], r_num[i]);
  for (int k = 0; k < 4; ++k) {
    for (std::size_t e = 0; e < j_auto[k].size(); ++e) {
      EXPECT_NEAR(j_auto[k][e], j_num[k][e], 1e-6 * (1.0 + std::abs(j_num[k][e])))
          << "block " << k << " entry " << e;
    }
  }
}

TEST(PoseGraph, RecoversExactMeasurementsFromADriftedStart) {
  // A closed square of 40 nodes; every edge measured exactly; the initial
  // estimates drift. The optimum is the truth.
  std::vector<Pose> truth;
  for (int i = 0; i < 40; ++i) {
    const double a = 2 * M_PI * i / 40;
    truth.push_back(make_pose(30 * std::cos(a), 30 * std::sin(a), 0.1 * std::sin(3 * a), 0, 0, a + M_PI / 2));
  }
  PoseGraph graph;
  for (int i = 0; i < 40; ++i) {
    const Pose drift = make_pose(0.05 * i, -0.03 * i, 0.01 * i, 0.002 * i, -0.001 * i, 0.004 * i);
    graph.add_node(truth[i] * drift);
  }
  const Matrix6d info = Matrix6d::Identity() * 100;
  for (int i = 1; i < 40; ++i) graph.add_edge({std::size_t(i - 1), std::size_t(i), truth[i - 1].inverse() * truth[i], info, EdgeKind::kOdometry});
  graph.add_edge({0, 39, truth[0].inverse() * truth[39], info, EdgeKind::kLoop});
  const PoseGraphSummary s = graph.optimize(PoseGraphOptions::from_config(SlamConfig{}));
  ASSERT_TRUE(s.usable);
  EXPECT_LT(s.final_cost, 1e-12);
  for (int i = 0; i < 40; ++i) {
    const Pose err = truth[i].inverse() * graph.pose(i);
    EXPECT_LT(err.translation().norm(), 1e-5) << i;
    EXPECT_LT(rotation_angle(err), 1e-6) << i;
  }
  EXPECT_TRUE(graph.pose(0).isApprox(truth[0], 1e-12));  // the first node is fixed
}

TEST(PoseGraph, OneLoopEdgeRemovesMostOfTheOdometryDrift) {
  // Odometry with a steady yaw bias drives a circle; one accurate loop edge
  // between the last and the first node pulls the estimate back.
  std::vector<Pose> truth;
  const int n = 120;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    truth.push_back(make_pose(50 * std::cos(a), 50 * std::sin(a), 0, 0, 0, a + M_PI / 2));
  }
  PoseGraph graph;
  graph.add_node(truth[0]);
  // Per step: 0.5 % scale and 0.03 deg of yaw (several times the odometry's real drift).
  const Pose bias = make_pose(0.005, 0.0, 0.0, 0, 0, 0.0005);
  Matrix6d odometry_info = Matrix6d::Identity();
  odometry_info.diagonal() << 1e4, 1e4, 1e4, 1e6, 1e6, 1e6;
  for (int i = 1; i < n; ++i) {
    const Pose measured = truth[i - 1].inverse() * truth[i] * bias;
    graph.add_node(graph.pose(i - 1) * measured);
    graph.add_edge({std::size_t(i - 1), std::size_t(i), measured, odometry_info, EdgeKind::kOdometry});
  }
  auto error = [&] {
    double sum = 0;
    for (int i = 0; i < n; ++i) sum += (graph.pose(i).translation() - truth[i].translation()).squaredNorm();
    return std::sqrt(sum / n);
  };
  const double before = error();
  ASSERT_GT(before, 1.0);
  graph.add_edge({0, std::size_t(n - 1), truth[0].inverse() * truth[n - 1], odometry_info, EdgeKind::kLoop});
  ASSERT_TRUE(graph.optimize(PoseGraphOptions::from_config(SlamConfig{})).usable);
  const double after = error();
  EXPECT_LT(after, 0.1 * before) << "before " << before << " m, after " << after << " m";
  // The error is spread over the chain: the loop edge keeps only a few
  // standard deviations of it (the robust phase left it its weight).
  EXPECT_LT(graph.edge_error(graph.edges().size() - 1).norm(), 5.0);
  // Rotations stay on the manifold.
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d R = graph.pose(i).rotation();
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  }
}

TEST(PoseGraph, RejectsBadEdges) {
  PoseGraph graph;
  graph.add_node(Pose::Identity());
  graph.add_node(Pose::Identity());
  EXPECT_THROW(graph.add_edge({0, 0, Pose::Identity(), Matrix6d::Identity(), EdgeKind::kOdometry}), std::invalid_argument);
  EXPECT_THROW(graph.add_edge({0, 5, Pose::Identity(), Matrix6d::Identity(), EdgeKind::kOdometry}), std::invalid_argument);
  EXPECT_THROW(graph.add_edge({0, 1, Pose::Identity(), -Matrix6d::Identity(), EdgeKind::kOdometry}), std::invalid_argument);
}

}  // namespace
}  // namespace saloam
