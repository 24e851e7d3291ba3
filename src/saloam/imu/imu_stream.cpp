#include "saloam/imu/imu_stream.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>
#include <fmt/format.h>

namespace saloam {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// rate, periods, gaps, backwards and repeated steps.
void time_stats(const std::vector<ImuSample>& samples, ImuStreamStats& s) {
  std::vector<double> steps;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    const double dt = samples[i].time - samples[i - 1].time;
    if (dt < 0.0) ++s.backwards_steps;
    if (dt == 0.0) ++s.repeated_times;
    if (dt > 0.0) steps.push_back(dt);
  }
  double forward = 0.0;
  for (const double dt : steps) forward += dt;
  s.rate_hz = forward > 0.0 ? static_cast<double>(steps.size()) / forward : 0.0;
  s.median_period_s = median(steps);
  s.largest_gap_s = steps.empty() ? 0.0 : *std::max_element(steps.begin(), steps.end());
}

/// The at-rest figures and the means over all samples.
void motion_stats(const std::vector<ImuSample>& samples, ImuStreamStats& s) {
  std::vector<double> gyro_norms;
  Eigen::Vector3d gyro_sum = Eigen::Vector3d::Zero(), gyro_sq = Eigen::Vector3d::Zero();
  double rest_norm_sum = 0.0, norm_sum = 0.0;
  for (const auto& sample : samples) {
    const double w = sample.angular_velocity.norm();
    gyro_norms.push_back(w);
    norm_sum += sample.acceleration.norm();
    s.mean_acceleration += sample.acceleration;
    if (!(w < kImuRestGyroRadS)) continue;
    ++s.rest_samples;
    rest_norm_sum += sample.acceleration.norm();
    gyro_sum += sample.angular_velocity;
    gyro_sq += sample.angular_velocity.cwiseAbs2();
  }
  if (samples.empty()) return;
  const auto n = static_cast<double>(samples.size());
  s.mean_acceleration /= n;
  s.mean_acceleration_norm = norm_sum / n;
  s.median_gyro_rad_s = median(gyro_norms);
  s.largest_gyro_rad_s = *std::max_element(gyro_norms.begin(), gyro_norms.end());
  const auto r = static_cast<double>(s.rest_samples);
  if (s.rest_samples > 0) s.gravity_at_rest = rest_norm_sum / r;
  if (s.rest_samples > 1) {
    // Per-axis sample variance (n - 1), then the mean over the axes.
    const Eigen::Vector3d variance = ((gyro_sq - gyro_sum.cwiseAbs2() / r) / (r - 1.0)).cwiseMax(0.0);
    s.gyro_noise_dps = std::sqrt(variance.mean()) / kDegToRad;
  }
}

void acceleration_problems(const ImuStreamStats& s, std::vector<std::string>& out) {
  const bool rest = s.rest_samples > 0;
  const double a = rest ? s.gravity_at_rest : s.mean_acceleration_norm;
  const std::string what = rest ? "at rest" : "over all samples (none at rest)";
  if (a > 0.7 && a < 1.5) {
    out.push_back(fmt::format("mean |a| {} is {:.3f}: about 1, acceleration read in g, not m/s^2 "
                              "(times {} wanted)", what, a, kStandardGravity));
  } else if (a < 0.9 * kStandardGravity || a > 1.2 * kStandardGravity) {
    out.push_back(fmt::format("mean |a| {} is {:.3f} m/s^2, far from gravity ({} m/s^2): wrong units or scale",
                              what, a, kStandardGravity));
  }
}

void gyro_problems(const ImuStreamStats& s, std::vector<std::string>& out) {
  if (s.largest_gyro_rad_s > 20.0) {
    out.push_back(fmt::format("angular velocity up to {:.1f} rad/s (over 20 rad/s): deg/s read as rad/s?",
                              s.largest_gyro_rad_s));
  }
  if (s.rest_samples == 0 && s.median_gyro_rad_s > 10.0 * kImuRestGyroRadS) {
    out.push_back(fmt::format("no sample with |w| under {} rad/s (median {:.2f} rad/s): the sensor never still, "
                              "or deg/s read as rad/s", kImuRestGyroRadS, s.median_gyro_rad_s));
  }
}

void time_problems(const ImuStreamStats& s, std::vector<std::string>& out) {
  if (s.backwards_steps > 0) out.push_back(fmt::format("time goes backwards {} times", s.backwards_steps));
  if (s.repeated_times > 0) {
    out.push_back(fmt::format("{} samples repeat the time before them (duplicated packets?)", s.repeated_times));
  }
  if (s.median_period_s > 0.0 && s.largest_gap_s > 3.0 * s.median_period_s) {
    out.push_back(fmt::format("a gap of {:.4f} s, {:.1f} times the median period {:.4f} s (samples lost)",
                              s.largest_gap_s, s.largest_gap_s / s.median_period_s, s.median_period_s));
  }
}

}  // namespace

ImuSample rotated(const ImuSample& sample, const Eigen::Matrix3d& rotation) {
  return {sample.time, rotation * sample.acceleration, rotation * sample.angular_velocity};
}

ImuStreamStats imu_stream_stats(const std::vector<ImuSample>& samples) {
  ImuStreamStats s;
  s.samples = samples.size();
  time_stats(samples, s);
  motion_stats(samples, s);
  return s;
}

std::vector<std::string> imu_stream_problems(const ImuStreamStats& s) {
  if (s.samples == 0) return {"no IMU samples"};
  std::vector<std::string> out;
  acceleration_problems(s, out);
  gyro_problems(s, out);
  time_problems(s, out);
  return out;
}

std::optional<Eigen::Vector3d> imu_up_at_rest(const std::vector<ImuSample>& samples, const Eigen::Matrix3d& rotation) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t still = 0;
  for (std::size_t i = 0; i < std::min(samples.size(), kImuUpSamples); ++i) {
    if (samples[i].angular_velocity.norm() >= kImuRestGyroRadS) continue;
    sum += samples[i].acceleration;
    ++still;
  }
  if (still < 5) return std::nullopt;
  const Eigen::Vector3d mean = sum / static_cast<double>(still);
  if (!mean.allFinite() || std::abs(mean.norm() / kStandardGravity - 1.0) > kImuRestTolerance) return std::nullopt;
  return (rotation * mean).normalized();
}

ImuStreamReport describe_imu_stream(const std::vector<ImuSample>& samples, const std::string& where,
                                    const Eigen::Matrix3d& rotation, const std::string& frame) {
  ImuStreamReport report;
  const ImuStreamStats stats = imu_stream_stats(samples);
  report.notes.push_back(fmt::format("IMU: {} samples {}, {:.0f} Hz, largest gap {:.3f} s; at rest ({} samples) |a| "
                                     "{:.3f} m/s^2 ({:.3f} g), gyroscope noise {:.2f} deg/s",
                                     stats.samples, where, stats.rate_hz, stats.largest_gap_s, stats.rest_samples,
                                     stats.gravity_at_rest, stats.gravity_at_rest / kStandardGravity, stats.gyro_noise_dps));
  for (const std::string& problem : imu_stream_problems(stats)) report.notes.push_back("IMU: " + problem);
  report.up = imu_up_at_rest(samples, rotation);
  if (report.up) {
    const Eigen::Vector3d& up = *report.up;
    report.notes.push_back(fmt::format("IMU: up ({:.3f}, {:.3f}, {:.3f}) in the {} frame, {:.1f} deg from its z", up.x(),
                                       up.y(), up.z(), frame, std::acos(std::clamp(up.z(), -1.0, 1.0)) / kDegToRad));
  }
  return report;
}

}  // namespace saloam
