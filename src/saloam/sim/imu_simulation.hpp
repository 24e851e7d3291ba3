#pragma once
// An IMU riding with the simulated sensor: the true specific force and
// angular velocity of a continuous motion, and samples of a named part with
// its white noise, bias random walk and turn-on bias (imu/imu_noise.hpp).
//
// Frames and units: the motion is T_W<-B (world z up, against gravity
// g = (0, 0, -kStandardGravity)); samples are in the body frame B, times [s]
// on the motion's clock; [m/s^2], [rad/s].

#include <cstdint>
#include <vector>

#include "saloam/imu/imu_noise.hpp"
#include "saloam/imu/imu_sample.hpp"
#include "saloam/sim/trajectories.hpp"

namespace saloam {

/// The true reading at time t: specific force R^T (a - g) and angular
/// velocity, by central differences over +-1 ms of the motion.
ImuSample true_imu_reading(const ContinuousMotion& motion, double t);

struct SimulatedImu {
  std::vector<ImuSample> samples;
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   ///< [rad/s] at the first sample
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  ///< [m/s^2] at the first sample
};

/// Samples every 1 / noise.rate_hz from t_begin through t_end (the last at
/// or after t_end): the true reading plus, when `noisy`, white noise, a
/// turn-on bias drawn from the part's spread and its random walk. The same
/// seed gives the same samples on every platform.
SimulatedImu simulate_imu(const ContinuousMotion& motion, double t_begin, double t_end, const ImuNoise& noise,
                          std::uint64_t seed, bool noisy = true);

}  // namespace saloam
