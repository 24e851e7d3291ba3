#include "saloam/imu/imu_noise.hpp"

#include <cmath>

#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace saloam {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kG = 9.80665;

// TDK InvenSense ICM-20948, the IMU inside Ouster OS0/OS1/OS2 sensors (read
// at 100 Hz in their IMU packets). Datasheet DS-000189 v1.3: gyroscope rate
// noise 0.015 deg/s/sqrt(Hz), accelerometer noise 230 ug/sqrt(Hz). The
// datasheet gives no bias instability: the random walks are those typical of
// consumer MEMS parts of its class in published Allan-variance fits. Bias at
// turn-on: the datasheet allows +-5 deg/s and +-50 mg uncalibrated; 0.5 deg/s
// and 20 mg (1 sigma) after the factory's calibration, as the real captures
// in ../shared suggest (at rest 1.01-1.05 g, gyroscopes within ~0.5 deg/s of
// 0: docs/imu.md).
ImuNoise icm20948() {
  ImuNoise n;
  n.name = "icm-20948";
  n.rate_hz = 100.0;
  n.gyro_noise_density = 0.015 * kDeg;
  n.gyro_bias_random_walk = 2.0e-5;
  n.gyro_bias_sigma = 0.5 * kDeg;
  n.accel_noise_density = 230e-6 * kG;
  n.accel_bias_random_walk = 4.0e-4;
  n.accel_bias_sigma = 0.020 * kG;
  return n;
}

// Analog Devices ADIS16465-1, an industrial IMU of survey and robotics rigs,
// read at 400 Hz here. Datasheet Rev. C: angle random walk 0.15 deg/sqrt(h),
// velocity random walk 0.012 m/s/sqrt(h), in-run bias stability 2 deg/h and
// 3.6 ug (the random walks below give about that drift over the Allan
// minimum's averaging time); bias repeatability 0.05 deg/s, 2 mg (1 sigma).
ImuNoise adis16465() {
  ImuNoise n;
  n.name = "adis16465";
  n.rate_hz = 400.0;
  n.gyro_noise_density = 0.15 * kDeg / 60.0;  // deg/sqrt(h) -> rad/s/sqrt(Hz)
  n.gyro_bias_random_walk = 1.0e-6;
  n.gyro_bias_sigma = 0.05 * kDeg;
  n.accel_noise_density = 0.012 / 60.0;  // m/s/sqrt(h) -> m/s^2/sqrt(Hz)
  n.accel_bias_random_walk = 2.0e-5;
  n.accel_bias_sigma = 0.002 * kG;
  return n;
}

}  // namespace

std::vector<std::string> imu_model_names() { return {"icm-20948", "adis16465"}; }

ImuNoise imu_model(const std::string& name) {
  if (name == "icm-20948") return icm20948();
  if (name == "adis16465") return adis16465();
  throw ConfigError(fmt::format("unknown IMU model '{}' (choose one of: {})", name, fmt::join(imu_model_names(), ", ")));
}

}  // namespace saloam
