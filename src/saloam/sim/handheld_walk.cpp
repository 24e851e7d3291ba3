#include "saloam/sim/handheld_walk.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "saloam/core/lie.hpp"

namespace saloam {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
constexpr double kSensorHeight = 1.73;  // [m] held up at head height: the simulated world's sensor height
constexpr double kPathLength = 120.0;   // [m] more than the walk covers

// 0 before 0, 1 after 1, the minimum-jerk polynomial between (peak slope 1.875).
double smooth_step(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
}

// Walking speed [m/s]: standing for the first second, 1.1-1.5 m/s while
// walking, two stops (looking behind, turning round in place).
double speed(double t) {
  const auto stop = [&](double from, double to) {  // slows over 1 s before `from`, walks again over 1 s after `to`
    return 1.0 - smooth_step(t - from + 1.0) + smooth_step(t - to);
  };
  return 1.3 * (1.0 + 0.12 * std::sin(2.0 * kPi * t / 11.0)) * smooth_step((t - 1.0) / 1.2) * stop(20.5, 24.5) *
         stop(43.0, 46.0);
}

// The path's curvature [1/m] at arc length s: a left and a right corner of
// 90 deg, each a smooth bump over 8 m (tightest radius 2.5 m).
double curvature(double s) {
  const auto corner = [&](double from, double angle) {
    const double length = 8.0, u = (s - from) / length;
    return (u < 0.0 || u > 1.0) ? 0.0 : angle / length * (1.0 - std::cos(2.0 * kPi * u));
  };
  return corner(22.0, 0.5 * kPi) + corner(46.0, -0.5 * kPi);
}

// A look around: the sensor turns by `angle` [deg] over `move` s from
// `start`, holds it for `hold` s and turns back (minimum-jerk moves: peak rate
// 1.875 * angle / move, up to ~190 deg/s).
struct LookAround {
  double start, angle, move, hold;
  [[nodiscard]] double yaw(double t) const {
    const double back = start + move + hold;
    return angle * kDeg * (smooth_step((t - start) / move) - smooth_step((t - back) / move));
  }
};
constexpr std::array<LookAround, 10> kLookArounds{{{5.0, 70, 0.7, 0.6},
                                                   {10.5, -90, 0.9, 0.8},
                                                   {15.0, 40, 0.45, 0.3},
                                                   {21.0, 180, 1.8, 1.0},  // standing: looks behind
                                                   {29.0, -60, 0.65, 0.5},
                                                   {34.0, 100, 1.0, 0.7},
                                                   {39.0, -45, 0.5, 0.4},
                                                   {43.5, -150, 1.5, 0.8},  // standing
                                                   {50.5, 80, 0.8, 0.5},
                                                   {55.0, -70, 0.75, 0.6}}};

// A sum of sines [rad]: a hand's tremor and slow drifts.
struct Wobble {
  double amplitude_deg, frequency_hz, phase;
  [[nodiscard]] double at(double t) const { return amplitude_deg * kDeg * std::sin(2.0 * kPi * frequency_hz * t + phase); }
};
constexpr std::array<Wobble, 3> kRollShake{{{0.35, 3.3, 0.2}, {0.2, 7.1, 1.3}, {1.5, 1.0 / 13.0, 0.0}}};
constexpr std::array<Wobble, 3> kPitchShake{{{0.35, 2.7, 2.1}, {0.2, 6.3, 0.7}, {2.0, 1.0 / 9.0, 0.5}}};
constexpr std::array<Wobble, 2> kYawShake{{{0.3, 3.9, 1.7}, {0.15, 5.7, 2.9}}};
constexpr double kHeldPitchDeg = 4.0;  // a hand holds the sensor's front a little down

template <std::size_t N>
double sum(const std::array<Wobble, N>& wobbles, double t) {
  double total = 0.0;
  for (const Wobble& w : wobbles) total += w.at(t);
  return total;
}

// Cubic Hermite interpolation between a and b (derivatives da, db per unit
// of u) at u in [0, 1]: the tables below are smooth to their second
// derivative's jumps, so that an IMU riding along reads no spikes.
double hermite(double a, double b, double da, double db, double u) {
  const double u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * a + (u3 - 2 * u2 + u) * da + (-2 * u3 + 3 * u2) * b + (u3 - u2) * db;
}

// Position of x in a table sampled every `step` from 0 (clamped): index and fraction.
std::pair<std::size_t, double> locate(std::size_t size, double step, double x) {
  const double f = std::clamp(x / step, 0.0, static_cast<double>(size - 1));
  const auto i = std::min(static_cast<std::size_t>(f), size - 2);
  return {i, f - static_cast<double>(i)};
}

// The steps' cadence [rad/s] at speed v: 1.4 Hz + 0.35 Hz per m/s (~1.85 steps/s at 1.3 m/s).
double cadence(double v) { return 2.0 * kPi * (1.4 + 0.35 * v); }

}  // namespace

HandheldWalk::HandheldWalk() {
  // Arc length and step phase by the midpoint rule; the cadence follows the
  // speed (1.4 Hz + 0.35 Hz per m/s: ~1.85 steps/s at 1.3 m/s).
  const auto samples = static_cast<std::size_t>(std::ceil(duration_ / time_step_)) + 1;
  walked_.assign(samples, 0.0);
  phase_.assign(samples, 0.0);
  for (std::size_t i = 1; i < samples; ++i) {
    const double v = speed((static_cast<double>(i) - 0.5) * time_step_);
    walked_[i] = walked_[i - 1] + v * time_step_;
    phase_[i] = phase_[i - 1] + cadence(v) * time_step_;
  }
  // The path from its curvature, heading +x from the origin.
  const auto path_samples = static_cast<std::size_t>(std::ceil(kPathLength / path_step_)) + 1;
  path_xy_.assign(path_samples, Eigen::Vector2d::Zero());
  path_heading_.assign(path_samples, 0.0);
  for (std::size_t i = 1; i < path_samples; ++i) {
    const double s_mid = (static_cast<double>(i) - 0.5) * path_step_;
    const double heading_mid = path_heading_[i - 1] + 0.5 * curvature(s_mid) * path_step_;
    path_heading_[i] = path_heading_[i - 1] + curvature(s_mid) * path_step_;
    path_xy_[i] = path_xy_[i - 1] + path_step_ * Eigen::Vector2d(std::cos(heading_mid), std::sin(heading_mid));
  }
  origin_inverse_ = Pose(Eigen::Translation3d(0.0, 0.0, kSensorHeight)).inverse();
}

double HandheldWalk::walked(double t) const {
  const auto [i, u] = locate(walked_.size(), time_step_, t);
  const double t0 = static_cast<double>(i) * time_step_;
  return hermite(walked_[i], walked_[i + 1], speed(t0) * time_step_, speed(t0 + time_step_) * time_step_, u);
}

double HandheldWalk::phase(double t) const {
  const auto [i, u] = locate(phase_.size(), time_step_, t);
  const double t0 = static_cast<double>(i) * time_step_;
  return hermite(phase_[i], phase_[i + 1], cadence(speed(t0)) * time_step_, cadence(speed(t0 + time_step_)) * time_step_, u);
}

void HandheldWalk::path_at(double s, Eigen::Vector2d& xy, double& heading) const {
  const auto [i, u] = locate(path_xy_.size(), path_step_, s);
  const double h0 = path_heading_[i], h1 = path_heading_[i + 1];
  xy.x() = hermite(path_xy_[i].x(), path_xy_[i + 1].x(), std::cos(h0) * path_step_, std::cos(h1) * path_step_, u);
  xy.y() = hermite(path_xy_[i].y(), path_xy_[i + 1].y(), std::sin(h0) * path_step_, std::sin(h1) * path_step_, u);
  const double s0 = static_cast<double>(i) * path_step_;
  heading = hermite(path_heading_[i], path_heading_[i + 1], curvature(s0) * path_step_, curvature(s0 + path_step_) * path_step_, u);
}

Pose HandheldWalk::track(double t) const {
  Eigen::Vector2d xy;
  double heading = 0.0;
  path_at(walked(t), xy, heading);
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(xy.x(), xy.y(), kSensorHeight);
  return rebased(T);
}

Pose HandheldWalk::sensor(double t) const {
  t = std::clamp(t, 0.0, duration_);
  Eigen::Vector2d xy;
  double heading = 0.0;
  path_at(walked(t), xy, heading);
  // The gait: a bob per step, a sway per stride (two steps), in proportion to the speed.
  const double gait = std::clamp(speed(t) / 1.3, 0.0, 1.2);
  const double phase = this->phase(t);
  const double bob = 0.03 * gait * std::cos(phase);
  const double sway = 0.025 * gait * std::sin(0.5 * phase);
  double look = 0.0;
  for (const LookAround& l : kLookArounds) look += l.yaw(t);
  const double yaw = heading + look + 2.0 * kDeg * gait * std::sin(0.5 * phase + 1.1) + sum(kYawShake, t);
  const double pitch = kHeldPitchDeg * kDeg + 1.5 * kDeg * gait * std::cos(phase + 0.6) + sum(kPitchShake, t);
  const double roll = 2.5 * kDeg * gait * std::sin(0.5 * phase + 0.4) + sum(kRollShake, t);
  const Eigen::Vector2d left(-std::sin(heading), std::cos(heading));
  Pose T = Pose::Identity();
  T.linear() = rotation_from_rpy(roll, pitch, yaw);
  T.translation() = Eigen::Vector3d(xy.x(), xy.y(), kSensorHeight + bob) + sway * Eigen::Vector3d(left.x(), left.y(), 0.0);
  return orthonormalized(rebased(T));
}

}  // namespace saloam
