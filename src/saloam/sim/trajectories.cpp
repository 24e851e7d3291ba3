#include "saloam/sim/trajectories.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <utility>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/sim/handheld_walk.hpp"

namespace saloam {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSpacing = 0.1;  // dense route sampling [m]

using Route = std::vector<Eigen::Vector2d>;

// Appends a parametric curve c(u), u in [u0, u1], resampled evenly.
void append_curve(Route& route, const std::function<Eigen::Vector2d(double)>& c, double u0, double u1) {
  const int fine = 20000;
  Eigen::Vector2d prev = c(u0);
  if (route.empty()) route.push_back(prev);
  double acc = (route.back() - prev).norm();
  for (int k = 1; k <= fine; ++k) {
    const Eigen::Vector2d p = c(u0 + (u1 - u0) * k / fine);
    acc += (p - prev).norm();
    prev = p;
    if (acc >= kSpacing) {
      route.push_back(p);
      acc = 0;
    }
  }
}

// Turtle pieces: straight and arc (positive angle = left turn).
struct Turtle {
  Eigen::Vector2d pos;
  double heading;
  void straight(Route& r, double length) {
    const int n = static_cast<int>(std::ceil(length / kSpacing));
    const Eigen::Vector2d dir(std::cos(heading), std::sin(heading));
    const Eigen::Vector2d start = pos;
    for (int k = 1; k <= n; ++k) r.push_back(start + dir * (length * k / n));
    pos = start + dir * length;
  }
  void arc(Route& r, double radius, double angle) {
    const double len = std::abs(angle) * radius;
    const int n = std::max(1, static_cast<int>(std::ceil(len / kSpacing)));
    const double sign = angle > 0 ? 1.0 : -1.0;
    const Eigen::Vector2d center = pos + sign * radius * Eigen::Vector2d(-std::sin(heading), std::cos(heading));
    const double h0 = heading;
    for (int k = 1; k <= n; ++k) {
      const double h = h0 + angle * k / n;
      r.push_back(center + sign * radius * Eigen::Vector2d(std::sin(h), -std::cos(h)));
    }
    heading = h0 + angle;
    pos = r.back();
  }
};

// Moving-average smoothing (keeps the ends fixed) so curvature changes gradually.
Route smooth(const Route& in, int half_window) {
  Route out(in.size());
  const int n = static_cast<int>(in.size());
  for (int i = 0; i < n; ++i) {
    const int w = std::min({half_window, i, n - 1 - i});
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (int k = -w; k <= w; ++k) sum += in[static_cast<std::size_t>(i + k)];
    out[static_cast<std::size_t>(i)] = sum / (2 * w + 1);
  }
  return out;
}

// Rolling hills; a function of position so that revisits agree.
double terrain_height(const Eigen::Vector2d& p) {
  return 1.6 * std::sin(p.x() / 95.0 + 0.4) + 1.1 * std::cos(p.y() / 70.0 - 0.3) + 0.4 * std::sin((p.x() + p.y()) / 40.0);
}

// The road surface under a place of the route: its height, and how much it
// rises per metre forward (the grade) and to the left (the cross-slope).
struct Surface {
  double height, grade, cross;
};
// The road surface at position p, heading dir, arc length s along the route.
using Relief = std::function<Surface(const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double s)>;

// The rolling hills as a road surface: slopes from the height a metre either side.
Surface on_rolling_hills(const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) {
  const Eigen::Vector2d left(-dir.y(), dir.x());
  return {terrain_height(p), (terrain_height(p + dir) - terrain_height(p - dir)) / 2.0,
          (terrain_height(p + left) - terrain_height(p - left)) / 2.0};
}

// Times the route with a curvature-limited speed profile and samples poses:
// the LiDAR sensor_height above the road, pitched with its grade and rolled
// with its cross-slope.
// World = the first LiDAR frame, or with `keep_level` its position and
// heading only (z stays up: a route that starts tilted keeps its world level).
std::vector<Pose> drive(const Route& route, double v_max, double frame_period, const Relief& relief = on_rolling_hills,
                        bool keep_level = false) {
  const std::size_t n = route.size();
  std::vector<double> s(n, 0.0), kappa(n, 0.0), v(n, v_max);
  for (std::size_t i = 1; i < n; ++i) s[i] = s[i - 1] + (route[i] - route[i - 1]).norm();
  const std::size_t w = 30;  // curvature from points 3 m apart
  for (std::size_t i = w; i + w < n; ++i) {
    const Eigen::Vector2d a = route[i] - route[i - w], b = route[i + w] - route[i];
    const double cross = a.x() * b.y() - a.y() * b.x();
    kappa[i] = std::abs(2.0 * cross / (a.norm() * b.norm() * (route[i + w] - route[i - w]).norm() + 1e-9));
  }
  const double lateral_acc = 1.8, accel = 1.0, decel = 1.6;
  for (std::size_t i = 0; i < n; ++i) v[i] = std::min(v_max, std::sqrt(lateral_acc / std::max(kappa[i], 1e-6)));
  v[0] = std::min(v[0], 7.0);
  for (std::size_t i = 1; i < n; ++i) {
    v[i] = std::min(v[i], std::sqrt(v[i - 1] * v[i - 1] + 2 * accel * (s[i] - s[i - 1])));
  }
  for (std::size_t i = n - 1; i-- > 0;) {
    v[i] = std::min(v[i], std::sqrt(v[i + 1] * v[i + 1] + 2 * decel * (s[i + 1] - s[i])));
  }
  // Time at each route sample, then poses every frame_period.
  std::vector<double> t(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) t[i] = t[i - 1] + (s[i] - s[i - 1]) / std::max(0.5 * (v[i] + v[i - 1]), 0.3);
  std::vector<Pose> poses;
  std::size_t j = 0;
  const double sensor_height = 1.73;
  for (double time = 0.0; time <= t.back(); time += frame_period) {
    while (j + 1 < n && t[j + 1] < time) ++j;
    const std::size_t k = std::min(j + 1, n - 1);
    const double a = t[k] > t[j] ? (time - t[j]) / (t[k] - t[j]) : 0.0;
    const Eigen::Vector2d p = route[j] + a * (route[k] - route[j]);
    const std::size_t i0 = j >= 20 ? j - 20 : 0, i1 = std::min(n - 1, j + 20);
    Eigen::Vector2d dir = route[i1] - route[i0];
    dir.normalize();
    const double yaw = std::atan2(dir.y(), dir.x());
    const Surface road = relief(p, dir, s[j] + a * (s[k] - s[j]));
    Pose T = Pose::Identity();
    T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-std::atan(road.grade), Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(std::atan(road.cross), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    T.translation() = Eigen::Vector3d(p.x(), p.y(), road.height + sensor_height);
    poses.push_back(orthonormalized(T));
  }
  Pose first = poses.front();
  if (keep_level) {
    const Eigen::Vector3d forward = first.linear().col(0);
    first.linear() = Eigen::AngleAxisd(std::atan2(forward.y(), forward.x()), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  }
  const Pose first_inv = first.inverse();
  for (auto& P : poses) P = orthonormalized(first_inv * P);
  return poses;
}

// Small lateral wander within the lane, a function of arc length.
Route wander(const Route& r, double amplitude, double wavelength) {
  Route out(r.size());
  double s = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (i > 0) s += (r[i] - r[i - 1]).norm();
    const std::size_t a = i > 0 ? i - 1 : i, b = std::min(r.size() - 1, i + 1);
    Eigen::Vector2d dir = r[b] - r[a];
    if (dir.norm() < 1e-9) dir = {1, 0};
    dir.normalize();
    out[i] = r[i] + amplitude * std::sin(2 * kPi * s / wavelength) * Eigen::Vector2d(-dir.y(), dir.x());
  }
  return out;
}

Route urban_loop() {
  // A rounded block (superellipse) with gently bent sides, driven 1.2 times.
  const double a = 150, b = 85, e = 2.0 / 6.0;
  auto c = [&](double u) {
    const double cu = std::cos(u), su = std::sin(u);
    const double r = 1.0 + 0.05 * std::sin(3 * u + 0.5);
    return Eigen::Vector2d(a * r * std::copysign(std::pow(std::abs(cu), e), cu),
                           b * r * std::copysign(std::pow(std::abs(su), e), su));
  };
  Route route;
  // Start on the south side heading east (u = -pi/2 + ...), go round counter-clockwise.
  const double u0 = -kPi / 2 - 0.35;
  append_curve(route, c, u0, u0 + 2 * kPi + 1.05);
  return wander(smooth(route, 30), 0.35, 170.0);
}

Route figure_eight() {
  // Lemniscate of Gerono; the two lobes cross in the middle at about 80 deg.
  const double A = 190, B = 150;
  auto c = [&](double u) { return Eigen::Vector2d(A * std::sin(u), 0.5 * B * std::sin(2 * u)); };
  Route route;
  append_curve(route, c, -0.25, 2 * kPi);
  // U-turn (a "light bulb" turn at a roundabout), ending in the opposite lane.
  const Eigen::Vector2d end_dir = (route.back() - route[route.size() - 2]).normalized();
  const double lane = 3.2;
  auto bulb = [&](double alpha, Route* out) {
    Turtle t{route.back(), std::atan2(end_dir.y(), end_dir.x())};
    Route tmp;
    t.straight(tmp, 25);
    t.arc(tmp, 12, -alpha);
    t.arc(tmp, 14, kPi + 2 * alpha);
    t.arc(tmp, 12, -alpha);
    if (out) *out = tmp;
    const Eigen::Vector2d rel = t.pos - route.back();
    return rel.dot(Eigen::Vector2d(-end_dir.y(), end_dir.x()));  // lateral offset to the left
  };
  double lo = 0.05, hi = 1.5;  // find alpha giving the lane offset
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (bulb(mid, nullptr) > lane ? lo : hi) = mid;
  }
  Route turn;
  bulb(0.5 * (lo + hi), &turn);
  route.insert(route.end(), turn.begin(), turn.end());
  // Back along the route in the opposite lane: the first lobe in reverse.
  Route reverse_part;
  append_curve(reverse_part, [&](double u) {
    const Eigen::Vector2d p = c(u);
    const double h = 1e-4;
    Eigen::Vector2d d = c(u + h) - c(u - h);
    d.normalize();
    return Eigen::Vector2d(p + lane * Eigen::Vector2d(-d.y(), d.x()));
  }, 2 * kPi, 2 * kPi - 2.6);
  // Connect the bulb's exit to the reversed route with a straight piece.
  const Eigen::Vector2d from = route.back(), to = reverse_part.front();
  const int n = static_cast<int>(std::ceil((to - from).norm() / kSpacing));
  for (int k = 1; k <= n; ++k) route.push_back(from + (to - from) * (static_cast<double>(k) / n));
  route.insert(route.end(), reverse_part.begin() + 1, reverse_part.end());
  return wander(smooth(route, 30), 0.25, 140.0);
}

Route straight_road() {
  Route route;
  append_curve(route, [](double u) { return Eigen::Vector2d(u, 25.0 * std::sin(u / 90.0)); }, 0.0, 400.0);
  return smooth(route, 30);
}

// A mountain road (the "hill-climb" preset): 2.7 km that climbs about
// 165 m in 1.6 km, over a crest down 80 m, through a sag and over a
// second, lower crest down 15 m. Its plan has open curves and three hairpins whose legs
// part at 30-40 degrees (a switchback's legs traverse the hillside).
Route hill_climb_plan() {
  Route r;
  Turtle t{{0.0, 0.0}, 0.0};
  r.push_back(t.pos);
  t.straight(r, 180);
  t.arc(r, 150, -0.6);
  t.straight(r, 160);
  t.arc(r, 90, 0.9);
  t.straight(r, 120);
  t.arc(r, 15, 2.6);  // left hairpin, 149 degrees
  t.straight(r, 200);
  t.arc(r, 15, -2.6);  // right hairpin
  t.straight(r, 180);
  t.arc(r, 120, 0.7);
  t.straight(r, 200);
  t.arc(r, 200, -0.5);
  t.straight(r, 150);
  t.arc(r, 16, -2.7);  // right hairpin, going down
  t.straight(r, 220);
  t.arc(r, 100, 0.8);
  t.straight(r, 200);
  t.arc(r, 140, -0.6);
  t.straight(r, 420);
  return wander(smooth(r, 30), 0.2, 150.0);
}

// The road of a route with a mountain road's profile, as a function of arc
// length. Grades: constant stretches of 8-15 % (breakpoint, grade) joined by
// vertical curves along which the grade changes linearly, 6 m per % of
// change (40-160 m: a crest from +12 % to -11 % takes 138 m, a radius of
// 600 m). Real mountain roads climb so: AASHTO's Green Book allows local
// roads in mountainous terrain 14-18 % at low design speeds, and Alpine
// passes hold 8-12 % for kilometres with ramps beyond (the Mortirolo
// averages about 10.5 % over 12 km). Cross-slope: 2.5 % falling to the
// right on straights (a one-way cross-fall for drainage), banked into the
// curves up to 6 % (a common maximum superelevation, e_max, on roads with
// snow and ice), the change spread over +-40 m of the curve's ends (the
// superelevation runoff); the first 60 m are level so that the first
// LiDAR frame, the world's frame, is level too.
class MountainProfile {
 public:
  explicit MountainProfile(const Route& route) : s_(route.size(), 0.0), z_(route.size(), 0.0), cross_(route.size(), 0.0) {
    const std::size_t n = route.size();
    for (std::size_t i = 1; i < n; ++i) s_[i] = s_[i - 1] + (route[i] - route[i - 1]).norm();
    for (std::size_t i = 1; i < n; ++i) z_[i] = z_[i - 1] + grade(0.5 * (s_[i] + s_[i - 1])) * (s_[i] - s_[i - 1]);
    // Signed curvature (left positive) from points 3 m apart, then averaged
    // over +-40 m.
    const std::size_t w = 30, run = 400;
    std::vector<double> kappa(n, 0.0), sum(n + 1, 0.0);
    for (std::size_t i = w; i + w < n; ++i) {
      const Eigen::Vector2d a = route[i] - route[i - w], b = route[i + w] - route[i];
      const double cross = a.x() * b.y() - a.y() * b.x();
      kappa[i] = 2.0 * cross / (a.norm() * b.norm() * (route[i + w] - route[i - w]).norm() + 1e-9);
    }
    for (std::size_t i = 0; i < n; ++i) sum[i + 1] = sum[i] + kappa[i];
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t a = i >= run ? i - run : 0, b = std::min(n, i + run + 1);
      const double mean_kappa = (sum[b] - sum[a]) / static_cast<double>(b - a);
      const double level = std::clamp((s_[i] - 30.0) / 30.0, 0.0, 1.0);  // level start, then in over 30 m
      cross_[i] = level * std::clamp(0.025 - 7.0 * mean_kappa, -0.06, 0.06);
    }
  }

  Surface operator()(const Eigen::Vector2d&, const Eigen::Vector2d&, double s) const {
    return {at(z_, s), (at(z_, s + 1.0) - at(z_, s - 1.0)) / 2.0, at(cross_, s)};
  }

 private:
  static double grade(double s) {
    static constexpr std::array<std::pair<double, double>, 13> kGrades{{{0, 0.0},
                                                                        {50, 0.09},
                                                                        {380, 0.13},
                                                                        {700, 0.15},
                                                                        {900, 0.10},
                                                                        {1080, 0.03},
                                                                        {1180, 0.12},
                                                                        {1560, -0.11},
                                                                        {1900, -0.14},
                                                                        {2150, -0.05},
                                                                        {2300, 0.08},
                                                                        {2480, -0.09},
                                                                        {1e9, -0.09}}};
    double g = kGrades.front().second;
    for (std::size_t k = 1; k < kGrades.size(); ++k) {
      const double change = kGrades[k].second - kGrades[k - 1].second;
      const double length = std::clamp(600.0 * std::abs(change), 40.0, 160.0);
      g += change * std::clamp((s - kGrades[k].first) / length + 0.5, 0.0, 1.0);
    }
    return g;
  }
  // Linear in arc length between route samples, clamped at the ends.
  double at(const std::vector<double>& f, double s) const {
    if (s <= s_.front()) return f.front();
    if (s >= s_.back()) return f.back();
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(s_.begin(), s_.end(), s) - s_.begin());
    const double a = (s - s_[k - 1]) / std::max(s_[k] - s_[k - 1], 1e-12);
    return f[k - 1] + a * (f[k] - f[k - 1]);
  }

  std::vector<double> s_, z_, cross_;
};

std::vector<Pose> hill_climb(double frame_period) {
  const Route route = hill_climb_plan();
  const MountainProfile profile(route);
  return drive(route, 12.0, frame_period, profile);
}

// The "ramp-start" preset: a car that starts on a garage ramp of 20 deg
// (36 % grade: steep, as garage ramps are) and drives up it for 30 m, levels
// out over the next 40 m (the grade falls linearly: a crest of ~110 m
// radius) and drives 1.3 km through town on level ground. Its world keeps z
// up, so the first scan is tilted 20 deg against gravity.
Route ramp_start_plan() {
  Route r;
  Turtle t{{0.0, 0.0}, 0.0};
  r.push_back(t.pos);
  t.straight(r, 160);
  t.arc(r, 40, -kPi / 2);
  t.straight(r, 220);
  t.arc(r, 60, kPi / 2);
  t.straight(r, 260);
  t.arc(r, 50, kPi / 3);
  t.straight(r, 180);
  t.arc(r, 45, -kPi / 2);
  t.straight(r, 200);
  return wander(smooth(r, 30), 0.2, 150.0);
}

std::vector<Pose> ramp_start(double frame_period) {
  constexpr double kRampGrade = 0.36397;  // tan 20 deg
  constexpr double kRampLength = 30.0, kLevelling = 40.0;  // [m]
  const auto grade = [&](double s) { return kRampGrade * std::clamp(1.0 - (s - kRampLength) / kLevelling, 0.0, 1.0); };
  const auto height = [&](double s) {
    const double ramp = std::min(s, kRampLength);
    const double u = std::clamp(s - kRampLength, 0.0, kLevelling);
    return kRampGrade * (ramp + u - 0.5 * u * u / kLevelling);
  };
  const Relief relief = [&](const Eigen::Vector2d&, const Eigen::Vector2d&, double s) {
    return Surface{height(s), grade(s), 0.0};
  };
  return drive(ramp_start_plan(), 10.0, frame_period, relief, true);
}

// A walk's poses (sensor or track) every frame_period over its duration.
std::vector<Pose> sampled(const HandheldWalk& walk, Pose (HandheldWalk::*pose)(double) const, double frame_period) {
  std::vector<Pose> poses;
  const auto frames = static_cast<std::size_t>(std::floor(walk.duration() / frame_period + 1e-9)) + 1;
  for (std::size_t i = 0; i < frames; ++i) poses.push_back((walk.*pose)(static_cast<double>(i) * frame_period));
  return poses;
}

ConfigError unknown_preset(const std::string& name) {
  return ConfigError(fmt::format("unknown preset '{}' (choose one of: {})", name, fmt::join(preset_names(), ", ")));
}

}  // namespace

std::vector<std::string> preset_names() {
  return {"urban-loop", "figure-eight", "straight", "hill-climb", "ramp-start", "handheld-walk"};
}

bool preset_on_hillside(const std::string& name) { return name == "hill-climb"; }

std::vector<Pose> preset_trajectory(const std::string& name, double frame_period) {
  if (frame_period <= 0) throw ConfigError("frame period must be positive");
  if (name == "urban-loop") return drive(urban_loop(), 11.0, frame_period);
  if (name == "figure-eight") return drive(figure_eight(), 11.5, frame_period);
  if (name == "straight") return drive(straight_road(), 10.0, frame_period);
  if (name == "hill-climb") return hill_climb(frame_period);
  if (name == "ramp-start") return ramp_start(frame_period);
  if (name == "handheld-walk") return sampled(HandheldWalk(), &HandheldWalk::sensor, frame_period);
  throw unknown_preset(name);
}

ContinuousMotion preset_motion(const std::string& name) {
  if (name != "handheld-walk") return {};
  return [walk = std::make_shared<const HandheldWalk>()](double t) { return walk->sensor(t); };
}

std::vector<Pose> preset_track(const std::string& name, double frame_period) {
  if (name != "handheld-walk") return preset_trajectory(name, frame_period);
  if (frame_period <= 0) throw ConfigError("frame period must be positive");
  return sampled(HandheldWalk(), &HandheldWalk::track, frame_period);
}

Pose kitti_velo_to_cam() {
  const double v[12] = {4.276802385584e-04,  -9.999672484946e-01, -8.084491683471e-03, -1.198459927713e-02,
                        -7.210626507497e-03, 8.081198471645e-03,  -9.999413164504e-01, -5.403984729748e-02,
                        9.999738645903e-01,  4.859485810390e-04,  -7.206933692422e-03, -2.921968648686e-01};
  return orthonormalized(pose_from_3x4(v));
}

}  // namespace saloam
