#pragma once
// The noise of real IMU parts as their datasheets and Allan-variance fits
// give it, in continuous time (the convention of Kalibr's imu.yaml and of
// IEEE Std 952): white noise densities and bias random walks per axis, plus
// the spread of the bias a part starts with. A sensor sampled at rate f has
// white noise of standard deviation density * sqrt(f) per sample, and its
// bias moves by random_walk / sqrt(f) per sample.

#include <string>
#include <vector>

namespace saloam {

struct ImuNoise {
  std::string name;
  double rate_hz = 100.0;                ///< samples per second
  double gyro_noise_density = 0.0;       ///< [rad/s/sqrt(Hz)]
  double gyro_bias_random_walk = 0.0;    ///< [rad/s^2/sqrt(Hz)]
  double gyro_bias_sigma = 0.0;          ///< [rad/s] a part's bias at turn-on, per axis (1 sigma)
  double accel_noise_density = 0.0;      ///< [m/s^2/sqrt(Hz)]
  double accel_bias_random_walk = 0.0;   ///< [m/s^3/sqrt(Hz)]
  double accel_bias_sigma = 0.0;         ///< [m/s^2] a part's bias at turn-on, per axis (1 sigma)
};

/// Names of the parts imu_model knows.
std::vector<std::string> imu_model_names();

/// A named part (imu_noise.cpp cites each value's source). ConfigError for
/// an unknown name, listing the known ones.
ImuNoise imu_model(const std::string& name);

}  // namespace saloam
