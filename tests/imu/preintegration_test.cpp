// IMU pre-integration (imu/preintegration.hpp) against the simulator's
// truth on the handheld walk: increments, bias Jacobians (numerically) and
// the propagated covariance (by Monte Carlo).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "saloam/core/lie.hpp"
#include "saloam/imu/imu_noise.hpp"
#include "saloam/imu/preintegration.hpp"
#include "saloam/sim/imu_simulation.hpp"
#include "saloam/sim/trajectories.hpp"

namespace saloam {
namespace {

constexpr double kDeg = M_PI / 180.0;
const Eigen::Vector3d kGravity(0.0, 0.0, -kStandardGravity);

// The true state of the walk's sensor at time t (velocity by central differences).
NavState true_state(const ContinuousMotion& motion, double t) {
  NavState s;
  s.rotation = motion(t).linear();
  s.position = motion(t).translation();
  s.velocity = (motion(t + 1e-4).translation() - motion(t - 1e-4).translation()) / 2e-4;
  return s;
}

struct PredictionError {
  double rotation_deg, position_m, velocity_mps;
};

PredictionError predict_frame(const ContinuousMotion& motion, const ImuNoise& part, double t0) {
  const SimulatedImu imu = simulate_imu(motion, t0 - 0.05, t0 + 0.15, part, 1, false);
  const ImuPreintegration pre = preintegrate(imu.samples, t0, t0 + 0.1);
  const NavState truth = true_state(motion, t0 + 0.1);
  const NavState predicted = pre.predict(true_state(motion, t0), kGravity);
  return {so3_log(truth.rotation.transpose() * predicted.rotation).norm() / kDeg,
          (truth.position - predicted.position).norm(), (truth.velocity - predicted.velocity).norm()};
}

// Over one frame (0.1 s) anywhere on the walk, the look-arounds included:
// noise-free samples predict the next state to within the sampling's own
// error (linear between samples, integrated at each interval's midpoint).
TEST(ImuPreintegration, PredictsTheWalkOverAFrame) {
  const ContinuousMotion motion = preset_motion("handheld-walk");
  for (const char* name : {"adis16465", "icm-20948"}) {
    const ImuNoise part = imu_model(name);
    PredictionError worst{0, 0, 0};
    for (double t0 = 0.3; t0 < 59.5; t0 += 0.7) {
      const PredictionError e = predict_frame(motion, part, t0);
      worst = {std::max(worst.rotation_deg, e.rotation_deg), std::max(worst.position_m, e.position_m),
               std::max(worst.velocity_mps, e.velocity_mps)};
    }
    std::printf("%s at %.0f Hz: worst over a frame %.4f deg, %.2f mm, %.1f mm/s\n", name, part.rate_hz, worst.rotation_deg,
                1e3 * worst.position_m, 1e3 * worst.velocity_mps);
    EXPECT_LT(worst.rotation_deg, 0.05) << name;
    EXPECT_LT(worst.position_m, 0.002) << name;
    EXPECT_LT(worst.velocity_mps, 0.03) << name;
  }
}

// The first-order bias correction against integrating again with the new
// biases: the residual shrinks with the square of the bias change.
TEST(ImuPreintegration, BiasJacobiansMatchIntegratingAgain) {
  const ContinuousMotion motion = preset_motion("handheld-walk");
  const SimulatedImu imu = simulate_imu(motion, 5.0, 5.3, imu_model("adis16465"), 1, false);
  const ImuPreintegration base = preintegrate(imu.samples, 5.05, 5.25);
  for (const double scale : {1e-2, 1e-3}) {
    const Eigen::Vector3d bg = scale * Eigen::Vector3d(0.3, -0.5, 0.4), ba = scale * Eigen::Vector3d(2.0, -1.0, 3.0);
    const ImuPreintegration again = preintegrate(imu.samples, 5.05, 5.25, bg, ba);
    const double rotation = so3_log(again.delta_rotation().transpose() * base.delta_rotation(bg)).norm();
    const double velocity = (again.delta_velocity() - base.delta_velocity(bg, ba)).norm();
    const double position = (again.delta_position() - base.delta_position(bg, ba)).norm();
    const double uncorrected = (again.delta_position() - base.delta_position()).norm();
    std::printf("bias change x%g: residual %.2e rad, %.2e m/s, %.2e m (uncorrected %.2e m)\n", scale, rotation, velocity,
                position, uncorrected);
    // Second order: about scale^2 times the first-order effect's size.
    EXPECT_LT(rotation, 50 * scale * scale);
    EXPECT_LT(velocity, 50 * scale * scale);
    EXPECT_LT(position, 10 * scale * scale);
    EXPECT_LT(position, 0.05 * uncorrected);
  }
}

// The propagated covariance against the scatter of many noisy
// integrations of one motion (white noise only, no bias).
TEST(ImuPreintegration, CovarianceMatchesTheScatterOfNoisyRuns) {
  const ContinuousMotion motion = preset_motion("handheld-walk");
  ImuNoise part = imu_model("icm-20948");
  part.gyro_bias_sigma = part.accel_bias_sigma = part.gyro_bias_random_walk = part.accel_bias_random_walk = 0.0;
  const double t0 = 5.5, t1 = 5.8;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  const ImuPreintegration clean = preintegrate(simulate_imu(motion, t0, t1, part, 1, false).samples, t0, t1, zero, zero, &part);
  const int runs = 400;
  Eigen::Matrix<double, 9, 9> scatter = Eigen::Matrix<double, 9, 9>::Zero();
  for (int r = 0; r < runs; ++r) {
    const ImuPreintegration noisy = preintegrate(simulate_imu(motion, t0, t1, part, 100 + r, true).samples, t0, t1);
    Eigen::Matrix<double, 9, 1> e;
    e << so3_log(clean.delta_rotation().transpose() * noisy.delta_rotation()),
        noisy.delta_velocity() - clean.delta_velocity(), noisy.delta_position() - clean.delta_position();
    scatter += e * e.transpose() / runs;
  }
  for (int i = 0; i < 9; ++i) {
    const double ratio = std::sqrt(scatter(i, i) / clean.covariance()(i, i));
    std::printf("state %d: sigma from the runs / propagated = %.3f\n", i, ratio);
    // 400 runs estimate a standard deviation to about +-3.5 % (1 sigma).
    EXPECT_GT(ratio, 0.85) << i;
    EXPECT_LT(ratio, 1.15) << i;
  }
}

TEST(ImuPreintegration, RefusesSamplesThatDoNotCoverTheInterval) {
  const std::vector<ImuSample> samples{{0.0, {0, 0, 9.8}, {0, 0, 0}}, {0.01, {0, 0, 9.8}, {0, 0, 0}}};
  EXPECT_THROW(preintegrate(samples, 0.0, 0.02), std::invalid_argument);
  EXPECT_THROW(preintegrate(samples, -0.01, 0.01), std::invalid_argument);
  EXPECT_NEAR(preintegrate(samples, 0.0, 0.01).delta_velocity().z(), 0.098, 1e-12);
}

// SO(3)'s right Jacobian: Exp(phi + d) ~ Exp(phi) Exp(J_r(phi) d).
TEST(ImuPreintegration, RightJacobianMatchesFiniteDifferences) {
  for (const Eigen::Vector3d& phi : {Eigen::Vector3d(0.3, -0.2, 0.9), Eigen::Vector3d(1e-7, 0, 0), Eigen::Vector3d(0, 2.5, 0.1)}) {
    const Eigen::Matrix3d J = so3_right_jacobian(phi);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = 1e-6 * Eigen::Vector3d::Unit(k);
      const Eigen::Vector3d numeric = so3_log(so3_exp(phi).transpose() * so3_exp(phi + d)) / 1e-6;
      EXPECT_LT((numeric - J.col(k)).norm(), 1e-5) << phi.transpose();
    }
  }
}

}  // namespace
}  // namespace saloam
