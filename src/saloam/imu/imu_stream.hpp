#pragma once
// An IMU stream described and checked, whatever its source (an Ouster's
// packets, a sequence's imu.txt): rate, gaps, gravity at rest, gyroscope
// noise, what looks wrong (units, time), and up from the samples at rest.
// Frames and units as imu_sample.hpp.

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "saloam/imu/imu_sample.hpp"

namespace saloam {

/// The sample with both vectors rotated by `rotation` (e.g. imu_to_lidar_rotation()).
[[nodiscard]] ImuSample rotated(const ImuSample& sample, const Eigen::Matrix3d& rotation);

/// Below this gyroscope norm a sample counts as at rest: 0.1 rad/s (5.7 deg/s),
/// several times an Ouster gyroscope's noise (0.3-0.5 deg/s per axis on the
/// still captures of ../shared/data/ouster_pcaps, norms up to 1.8 deg/s).
inline constexpr double kImuRestGyroRadS = 0.1;

struct ImuStreamStats {
  std::size_t samples = 0;
  double rate_hz = 0.0;            ///< steps forward per second of them; 0 with fewer than 2 distinct times
  double median_period_s = 0.0;    ///< of the steps forward
  double largest_gap_s = 0.0;      ///< the longest step forward
  std::size_t backwards_steps = 0; ///< samples earlier than the one before
  std::size_t repeated_times = 0;  ///< samples at the same time as the one before
  std::size_t rest_samples = 0;    ///< gyroscope norm below kImuRestGyroRadS
  /// [m/s^2] mean |a| over the rest samples; NaN without any
  double gravity_at_rest = std::numeric_limits<double>::quiet_NaN();
  /// [deg/s] per-axis standard deviation (RMS over x, y, z) over the rest samples; NaN with under 2
  double gyro_noise_dps = std::numeric_limits<double>::quiet_NaN();
  double mean_acceleration_norm = 0.0;  ///< [m/s^2] mean |a| over all samples
  double largest_gyro_rad_s = 0.0;      ///< [rad/s] largest gyroscope norm
  double median_gyro_rad_s = 0.0;       ///< [rad/s] median gyroscope norm
  Eigen::Vector3d mean_acceleration = Eigen::Vector3d::Zero();  ///< [m/s^2] over all samples
};

[[nodiscard]] ImuStreamStats imu_stream_stats(const std::vector<ImuSample>& samples);

/// What looks wrong, one sentence each; empty when all is plausible: no
/// samples; |a| near 1 (g read as m/s^2) or far from gravity otherwise;
/// angular velocities over 20 rad/s, or never near 0 (deg/s read as rad/s);
/// time going backwards or repeating; a gap over 3 median periods.
[[nodiscard]] std::vector<std::string> imu_stream_problems(const ImuStreamStats& stats);

/// Up (unit, against gravity) in the frame `rotation` turns the samples into
/// (R_to<-imu, e.g. imu_to_lidar_rotation()): the direction of the mean
/// specific force over the samples at rest (kImuRestGyroRadS) among the
/// first kImuUpSamples, which at rest is gravity's reaction. Nothing with
/// fewer than 5 such samples or a mean magnitude more than kImuRestTolerance
/// from 1 g (the sensor was accelerating, or the units are wrong: the
/// moving OS1-128 capture of ../shared reads 1.089 g, its forward
/// acceleration or vibration tilting the mean 22 deg; the still ones
/// 1.011-1.029 g).
/// A sensor that turns little but moves passes for one at rest: the
/// handheld walk's first 2 s (standing, then setting off) put up 2.6 deg
/// off (docs/imu.md).
inline constexpr std::size_t kImuUpSamples = 200;
inline constexpr double kImuRestTolerance = 0.05;
[[nodiscard]] std::optional<Eigen::Vector3d> imu_up_at_rest(const std::vector<ImuSample>& samples,
                                                            const Eigen::Matrix3d& rotation);

/// What a source says of its IMU stream: notes for `saloam info` (counts,
/// rate, gaps, gravity and gyroscope noise at rest, each problem) and the up
/// it gives (imu_up_at_rest). `where` names the stream ("on port 7503", "in
/// imu.txt"), `frame` the frame `rotation` turns the samples into.
struct ImuStreamReport {
  std::vector<std::string> notes;
  std::optional<Eigen::Vector3d> up;
};
[[nodiscard]] ImuStreamReport describe_imu_stream(const std::vector<ImuSample>& samples, const std::string& where,
                                                  const Eigen::Matrix3d& rotation, const std::string& frame);

}  // namespace saloam
