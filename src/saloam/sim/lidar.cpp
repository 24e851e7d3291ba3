#include "saloam/sim/lidar.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"

namespace saloam {
namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

LidarModel LidarModel::hdl64e(int beams) {
  if (beams != 64 && beams != 32 && beams != 16) throw ConfigError("beams must be 64, 32 or 16");
  LidarModel m;
  std::vector<double> all;
  for (int i = 0; i < 32; ++i) all.push_back(2.0 - (2.0 + 8.33) * i / 31.0);
  for (int i = 0; i < 32; ++i) all.push_back(-8.83 - (24.9 - 8.83) * i / 31.0);
  const int step = 64 / beams;
  for (int i = 0; i < 64; i += step) m.elevation_deg.push_back(all[static_cast<std::size_t>(i)]);
  m.ego_body = kitti_ego_body();
  return m;
}

LidarModel LidarModel::from_profile(const SensorProfile& profile) {
  if (!profile.sweep_clockwise || std::abs(profile.sweep_start_azimuth_deg - 180.0) > 1e-9) {
    throw ConfigError(profile.name + ": the simulator renders sweeps turning clockwise from behind (sweep_clockwise "
                                     "true, sweep_start_azimuth_deg 180)");
  }
  LidarModel m;
  m.elevation_deg = profile.elevation_deg;
  m.azimuth_steps = profile.simulation.azimuth_steps;
  m.min_range = profile.min_range;
  m.max_range = profile.max_range;
  m.range_noise = profile.simulation.range_noise;
  m.sweep_period = profile.sweep_duration;
  if (profile.simulation.kitti_ego_body) m.ego_body = kitti_ego_body();
  return m;
}

std::vector<Eigen::AlignedBox3d> LidarModel::kitti_ego_body() {
  constexpr double kSensorHeight = 1.73, kBeltLine = 0.93, kRoof = 1.45;
  return {Eigen::AlignedBox3d(Eigen::Vector3d(-2.39, -0.91, -kSensorHeight), Eigen::Vector3d(2.03, 0.91, kBeltLine - kSensorHeight)),
          Eigen::AlignedBox3d(Eigen::Vector3d(-0.84, -0.45, -kSensorHeight), Eigen::Vector3d(0.30, 0.45, kRoof - kSensorHeight))};
}

bool LidarModel::hits_ego_body(const Eigen::Vector3d& direction) const {
  // Slab test of the ray from the origin (outside every box) against each box.
  return std::any_of(ego_body.begin(), ego_body.end(), [&](const Eigen::AlignedBox3d& box) {
    double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (std::abs(direction[a]) < 1e-12) {
        if (box.min()[a] > 0.0 || box.max()[a] < 0.0) return false;
        continue;
      }
      double lo = box.min()[a] / direction[a], hi = box.max()[a] / direction[a];
      if (lo > hi) std::swap(lo, hi);
      t0 = std::max(t0, lo);
      t1 = std::min(t1, hi);
    }
    return t0 <= t1;
  });
}

double LidarModel::column_fraction(int column) const { return (column + 0.5) / azimuth_steps; }

double LidarModel::column_azimuth(int column) const { return kPi - 2.0 * kPi * column_fraction(column); }

Pose column_pose(const LidarModel& lidar, const SweepSpec& sweep, int column) {
  if (!sweep.skew) return sweep.start;
  const double fraction = lidar.column_fraction(column);
  if (sweep.knots.size() < 2) return interpolate(sweep.start, sweep.end, fraction);
  const double f = fraction * static_cast<double>(sweep.knots.size() - 1);
  const auto i = std::min(static_cast<std::size_t>(f), sweep.knots.size() - 2);
  return interpolate(sweep.knots[i], sweep.knots[i + 1], f - static_cast<double>(i));
}

std::vector<Eigen::Vector3d> points_in_world(const SimulatedScan& scan, const LidarModel& lidar, const SweepSpec& sweep) {
  std::vector<Eigen::Vector3d> out(scan.cloud.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = column_pose(lidar, sweep, scan.column.at(i)) * scan.cloud.points[i].cast<double>();
  }
  return out;
}

SweepRays::SweepRays(const LidarModel& lidar, const Eigen::Matrix3d& mount) : columns(lidar.azimuth_steps) {
  const int beams = lidar.beams();
  if (columns <= 0 || beams <= 0) throw ConfigError("lidar model needs beams and azimuth steps");
  for (int b = 0; b < beams; ++b) {
    const double e = lidar.elevation_deg[static_cast<std::size_t>(b)] * kPi / 180.0;
    sin_el.push_back(std::sin(e));
    cos_el.push_back(std::cos(e));
  }
  for (int c = 0; c < columns; ++c) {
    const double az = lidar.column_azimuth(c);
    cos_az.push_back(std::cos(az));
    sin_az.push_back(std::sin(az));
  }
  blocked.assign(static_cast<std::size_t>(beams) * static_cast<std::size_t>(columns), 0);
  for (int b = 0; b < beams && !lidar.ego_body.empty(); ++b) {
    for (int c = 0; c < columns; ++c) {
      blocked[static_cast<std::size_t>(b) * static_cast<std::size_t>(columns) + static_cast<std::size_t>(c)] =
          lidar.hits_ego_body(mount * direction(b, c)) ? 1 : 0;
    }
  }
}

SimulatedScan simulate_scan(const World& world, const LidarModel& lidar, const SweepSpec& sweep) {
  return simulate_scan(world, lidar, SweepRays(lidar), sweep);
}

namespace {

/// One range-image cell's return, in the sensor frame at its column's instant.
struct CellReturn {
  Eigen::Vector3f point = Eigen::Vector3f::Zero();
  float remission = 0;
  float range = 0;  ///< [m]
  std::uint16_t label = 0, instance = 0;
  bool valid = false;
};

/// [m] How far above or below the sensor a moving object's parts reach at most.
constexpr double kAgentVerticalReach = 6.0;

/// The moving objects `agents` near the plane of a column's rays (the plane
/// through the sensor at `origin` with unit normal `normal`, which is
/// vertical for a level sensor): not behind the sensor looking along
/// `heading`, and within their footprint radius of the plane (widened by
/// how far a tilted plane leans over their height).
void agents_near_plane(const std::vector<Primitive>& agents, const Eigen::Vector2d& origin,
                       const Eigen::Vector3d& heading, const Eigen::Vector3d& normal, std::vector<Primitive>& near) {
  Eigen::Vector2d h2 = heading.head<2>();
  if (h2.norm() > 1e-9) h2.normalize();
  const double level = normal.head<2>().norm();
  const Eigen::Vector2d n2 = level > 1e-9 ? Eigen::Vector2d(normal.head<2>() / level) : Eigen::Vector2d::Zero();
  const double lean = level > 1e-9 ? std::abs(normal.z()) / level * kAgentVerticalReach
                                   : std::numeric_limits<double>::infinity();
  near.clear();
  for (const auto& p : agents) {
    const Eigen::Vector2d rel = p.center.cast<double>() - origin;
    const double along = rel.dot(h2), across = std::abs(rel.dot(n2));
    const double radius = p.footprint_radius();
    if (along > -radius - lean && across < radius + 0.05 + lean) near.push_back(p);
  }
}

/// What the sensor reports of a ray (direction `dir_s` in the sensor frame)
/// that met `hit`: range noise, dropout (weak far returns from dark surfaces
/// are lost more often) and remission noise. Every random number is drawn
/// whether or not it is used, so that one ray's outcome never shifts the
/// noise of the next.
CellReturn sensor_return(const RayHit& hit, const Eigen::Vector3d& dir_s, const LidarModel& lidar, Rng& rng) {
  const double noise = rng.normal() * lidar.range_noise;
  const double drop = rng.uniform();
  const double rem_noise = rng.normal() * lidar.remission_noise;
  CellReturn out;
  if (!hit.hit) return out;
  const double range_m = hit.range + noise;
  if (range_m < lidar.min_range || range_m > lidar.max_range) return out;
  const double far = range_m / lidar.max_range;
  const double p_drop = lidar.dropout + 0.25 * far * far * (1.0 - std::min(1.0, static_cast<double>(hit.remission) * 2.0));
  if (drop < p_drop) return out;
  // A spinning LiDAR reports each return in its own frame at the
  // column's instant: the scan is distorted by the motion during the
  // sweep (pose `start` names the sweep, not every point's frame).
  out.point = (range_m * dir_s).cast<float>();
  out.remission = static_cast<float>(std::clamp(hit.remission + rem_noise, 0.0, 0.99));
  out.range = static_cast<float>(range_m);
  out.label = hit.label;
  out.instance = hit.instance;
  out.valid = true;
  return out;
}

/// A range image of returns, ring by ring.
class ReturnGrid {
 public:
  ReturnGrid(int beams, int columns)
      : beams_(beams), columns_(columns), cells_(static_cast<std::size_t>(columns) * static_cast<std::size_t>(beams)) {}
  CellReturn& at(int beam, int column) { return cells_[index(beam, column)]; }
  [[nodiscard]] const CellReturn& at(int beam, int column) const { return cells_[index(beam, column)]; }
  [[nodiscard]] int beams() const { return beams_; }
  [[nodiscard]] int columns() const { return columns_; }
  [[nodiscard]] std::size_t valid() const {
    return static_cast<std::size_t>(std::count_if(cells_.begin(), cells_.end(), [](const CellReturn& r) { return r.valid; }));
  }

 private:
  [[nodiscard]] std::size_t index(int beam, int column) const {
    return static_cast<std::size_t>(beam) * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(column);
  }
  int beams_, columns_;
  std::vector<CellReturn> cells_;
};

/// Casts column `c`'s rays into `grid` (`agents`, `near`: scratch); returns
/// the height of the rays' origin over the sensor pose [m].
float render_column(const World& world, const LidarModel& lidar, const SweepRays& rays, const SweepSpec& sweep, int c,
                    std::vector<Primitive>& agents, std::vector<Primitive>& near, ReturnGrid& grid) {
  const double frac = lidar.column_fraction(c);
  const Pose sensor = column_pose(lidar, sweep, c);
  const double t = sweep.skew ? sweep.time_start + frac * (sweep.time_end - sweep.time_start) : sweep.time_start;
  const double cos_az = rays.cos_az[static_cast<std::size_t>(c)], sin_az = rays.sin_az[static_cast<std::size_t>(c)];
  // The sensor stays on a car on the ground (World::sensor_origin); the
  // points are in the sensor frame, so a height error of the pose, if
  // any, shows up as it does in real data: between poses and scans.
  const World::RayOrigin rays_from = world.ray_origin(world.sensor_origin(sensor.translation()));
  const Eigen::Vector3d& origin = rays_from.position;
  // Moving objects at this column's time, kept only near the column's vertical plane.
  world.agents_at(t, origin.head<2>(), lidar.max_range + 10.0, agents);
  agents_near_plane(agents, origin.head<2>(), sensor.linear() * Eigen::Vector3d(cos_az, sin_az, 0.0),
                    sensor.linear() * Eigen::Vector3d(-sin_az, cos_az, 0.0), near);
  Rng rng(hash3(sweep.seed, 0x5ca7ull, static_cast<std::uint64_t>(c)));
  for (int b = 0; b < grid.beams(); ++b) {
    CellReturn& out = grid.at(b, c);
    out.valid = false;
    if (rays.is_blocked(b, c)) continue;
    const Eigen::Vector3d dir_s = rays.direction(b, c);
    const RayHit hit = world.cast_ray(rays_from, sensor.linear() * dir_s, lidar.max_range, t, near, rng);
    out = sensor_return(hit, dir_s, lidar, rng);
  }
  return static_cast<float>(origin.z() - sensor.translation().z());
}

/// The scan of the grid's returns, ring by ring, with each point's ring and
/// time in the sweep.
SimulatedScan scan_of(const ReturnGrid& grid, const LidarModel& lidar, const SweepSpec& sweep) {
  SimulatedScan scan;
  const double sweep_span = sweep.skew ? sweep.time_end - sweep.time_start : 0.0;
  const std::size_t count = grid.valid();
  scan.cloud.reserve(count);
  scan.ring.reserve(count);
  scan.column.reserve(count);
  scan.range.reserve(count);
  for (int b = 0; b < grid.beams(); ++b) {
    for (int c = 0; c < grid.columns(); ++c) {
      const CellReturn& r = grid.at(b, c);
      if (!r.valid) continue;
      scan.cloud.push_back(r.point, r.remission, r.label, r.instance);
      scan.ring.push_back(static_cast<std::uint16_t>(b));
      scan.column.push_back(static_cast<std::uint16_t>(c));
      scan.range.push_back(r.range);
    }
  }
  // Ring and time fields after the points (push_back drops them).
  scan.cloud.ring = scan.ring;
  scan.cloud.time.resize(scan.column.size());
  for (std::size_t i = 0; i < scan.column.size(); ++i) {
    scan.cloud.time[i] = static_cast<float>(lidar.column_fraction(scan.column[i]) * sweep_span);
  }
  scan.cloud.has_labels = true;
  return scan;
}

}  // namespace

SimulatedScan simulate_scan(const World& world, const LidarModel& lidar, const SweepRays& rays, const SweepSpec& sweep) {
  const int columns = lidar.azimuth_steps, beams = lidar.beams();
  if (rays.columns != columns || static_cast<int>(rays.sin_el.size()) != beams) {
    throw ConfigError("ray table of another lidar model");
  }
  ReturnGrid grid(beams, columns);
  std::vector<float> column_offset(static_cast<std::size_t>(columns), 0.0f);
  tbb::parallel_for(tbb::blocked_range<int>(0, columns, 16), [&](const tbb::blocked_range<int>& range) {
    std::vector<Primitive> agents, near;
    for (int c = range.begin(); c < range.end(); ++c) {
      column_offset[static_cast<std::size_t>(c)] = render_column(world, lidar, rays, sweep, c, agents, near, grid);
    }
  });
  SimulatedScan scan = scan_of(grid, lidar, sweep);
  for (const float dz : column_offset) {
    if (std::abs(dz) > std::abs(scan.sensor_offset)) scan.sensor_offset = dz;
  }
  return scan;
}

}  // namespace saloam
