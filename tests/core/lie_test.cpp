#include <gtest/gtest.h>

#include <random>

#include "saloam/core/lie.hpp"

namespace saloam {
namespace {

Vector6d random_twist(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, scale);
  Vector6d xi;
  for (int i = 0; i < 6; ++i) xi(i) = n(rng);
  return xi;
}

TEST(Lie, ExpLogRoundTrip) {
  std::mt19937 rng(7);
  for (double scale : {1e-9, 1e-4, 0.1, 1.0}) {
    for (int k = 0; k < 50; ++k) {
      const Vector6d xi = random_twist(rng, scale);
      if (xi.tail<3>().norm() > 3.0) continue;  // stay below pi
      const Vector6d back = se3_log(se3_exp(xi));
      EXPECT_LT((back - xi).norm(), 1e-9 + 1e-9 * xi.norm()) << "scale " << scale;
    }
  }
}

TEST(Lie, ExpOfPureRotationAndTranslation) {
  Vector6d xi = Vector6d::Zero();
  xi(5) = M_PI / 2;  // yaw 90 deg
  const Pose T = se3_exp(xi);
  EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  xi.setZero();
  xi.head<3>() = Eigen::Vector3d(1, 2, 3);
  EXPECT_TRUE(se3_exp(xi).translation().isApprox(Eigen::Vector3d(1, 2, 3)));
}

TEST(Lie, So3LogNearPi) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, -1).normalized();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI - 1e-7, axis).toRotationMatrix();
  const Eigen::Vector3d phi = so3_log(R);
  EXPECT_NEAR(phi.norm(), M_PI - 1e-7, 1e-6);
  EXPECT_TRUE(so3_exp(phi).isApprox(R, 1e-9));
}

TEST(Lie, OrthonormalizeRemovesDrift) {
  std::mt19937 rng(3);
  Pose T = Pose::Identity();
  Pose step = se3_exp(random_twist(rng, 0.05));
  step.linear() *= 1.0 + 1e-6;  // a slightly non-orthonormal increment, as from float text files
  for (int i = 0; i < 10000; ++i) T = orthonormalized(T * step);
  const Eigen::Matrix3d R = T.linear();
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
}

TEST(Lie, InterpolateEndpointsAndMidpoint) {
  Vector6d xi = Vector6d::Zero();
  xi << 2.0, 0.0, 0.0, 0.0, 0.0, 0.4;
  const Pose a = Pose::Identity();
  const Pose b = se3_exp(xi);
  EXPECT_TRUE(interpolate(a, b, 0.0).isApprox(a, 1e-12));
  EXPECT_TRUE(interpolate(a, b, 1.0).isApprox(b, 1e-12));
  const Pose mid = interpolate(a, b, 0.5);
  EXPECT_NEAR(rotation_angle(mid), 0.2, 1e-12);
  EXPECT_TRUE(mid.translation().isApprox(0.5 * b.translation(), 1e-12));
}

TEST(Lie, Pose3x4RoundTrip) {
  std::mt19937 rng(11);
  const Pose T = se3_exp(random_twist(rng, 0.7));
  double v[12];
  pose_to_3x4(T, v);
  EXPECT_TRUE(pose_from_3x4(v).isApprox(T, 1e-15));
  EXPECT_DOUBLE_EQ(v[3], T.translation().x());
  EXPECT_DOUBLE_EQ(v[4], T.linear()(1, 0));
}

}  // namespace
}  // namespace saloam
