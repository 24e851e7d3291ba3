#include "saloam/sim/imu_simulation.hpp"

#include <cmath>

#include "saloam/core/lie.hpp"
#include "saloam/sim/random.hpp"

namespace saloam {
namespace {
constexpr double kStep = 1e-3;  // [s] central differences
}  // namespace

ImuSample true_imu_reading(const ContinuousMotion& motion, double t) {
  const Pose before = motion(t - kStep), now = motion(t), after = motion(t + kStep);
  const Eigen::Vector3d acceleration =
      (after.translation() - 2.0 * now.translation() + before.translation()) / (kStep * kStep);
  const Eigen::Vector3d gravity(0.0, 0.0, -kStandardGravity);
  ImuSample s;
  s.time = t;
  s.acceleration = now.linear().transpose() * (acceleration - gravity);
  s.angular_velocity = so3_log(before.linear().transpose() * after.linear()) / (2.0 * kStep);
  return s;
}

SimulatedImu simulate_imu(const ContinuousMotion& motion, double t_begin, double t_end, const ImuNoise& noise,
                          std::uint64_t seed, bool noisy) {
  SimulatedImu out;
  Rng rng(seed);
  const auto vector = [&](double sigma) {  // x, y, z drawn in that order (arguments' order is unspecified)
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = rng.normal(0.0, sigma);
    return v;
  };
  const double dt = 1.0 / noise.rate_hz;
  if (noisy) {
    out.gyro_bias = vector(noise.gyro_bias_sigma);
    out.accel_bias = vector(noise.accel_bias_sigma);
  }
  Eigen::Vector3d gyro_bias = out.gyro_bias, accel_bias = out.accel_bias;
  // Discrete per-sample standard deviations of the continuous densities.
  const double gyro_white = noise.gyro_noise_density / std::sqrt(dt), accel_white = noise.accel_noise_density / std::sqrt(dt);
  const double gyro_walk = noise.gyro_bias_random_walk * std::sqrt(dt), accel_walk = noise.accel_bias_random_walk * std::sqrt(dt);
  const auto count = static_cast<std::size_t>(std::ceil((t_end - t_begin) / dt - 1e-9)) + 1;
  for (std::size_t k = 0; k < count; ++k) {
    ImuSample s = true_imu_reading(motion, t_begin + static_cast<double>(k) * dt);
    if (noisy) {
      s.angular_velocity += gyro_bias + vector(gyro_white);
      s.acceleration += accel_bias + vector(accel_white);
      gyro_bias += vector(gyro_walk);
      accel_bias += vector(accel_walk);
    }
    out.samples.push_back(s);
  }
  return out;
}

}  // namespace saloam
