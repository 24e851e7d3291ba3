#pragma once
// A spinning multi-beam LiDAR (Velodyne HDL-64E as in KITTI by default, or
// any sensor profile of core/sensor_profile.hpp) and the ray casting of one
// sweep in a simulated World.
//
// Sweep convention: the head spins clockwise seen from above (azimuth
// decreasing), starting and ending behind the car (azimuth +-180 deg), like
// KITTI's scans. Column c is fired at time t0 + period * (c + 0.5) / columns
// at azimuth pi - 2 pi (c + 0.5) / columns. Points are written ring by ring
// (top beam first), each ring in firing order. With skew on, each return is
// in the sensor frame at its own column's instant, as a real spinning LiDAR
// reports it (motion-distorted); the frame's pose is the pose at sweep start,
// so de-skewing a point of time fraction s = (pi - azimuth) / (2 pi) into the
// sweep-start frame uses the motion from pose i towards pose i+1. Each point
// carries its beam (LabelledCloud::ring, 0 = top) and its column's time
// (LabelledCloud::time, seconds after the sweep start, the scan's timestamp),
// as a driver's clouds do.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "saloam/core/sensor_profile.hpp"
#include "saloam/core/types.hpp"
#include "saloam/sim/world.hpp"

namespace saloam {

struct LidarModel {
  std::vector<double> elevation_deg;  ///< beam elevations, top to bottom
  int azimuth_steps = 2083;           ///< columns per turn
  double min_range = 2.5, max_range = 120.0;
  double range_noise = 0.02;          ///< Gaussian sigma [m]
  double dropout = 0.05;              ///< probability that a return is lost
  double sweep_period = 0.1;          ///< [s]
  double remission_noise = 0.04;
  /// The recording car's body in the sensor frame (x forward, z up): rays
  /// that meet it return nothing. Empty = a free-standing sensor.
  std::vector<Eigen::AlignedBox3d> ego_body;

  /// HDL-64E: upper block of 32 beams from +2 to -8.33 deg, lower block of 32
  /// from -8.83 to -24.9 deg. With beams = 32 or 16, every 2nd / 4th beam.
  /// Mounted on KITTI's car (kitti_ego_body()).
  static LidarModel hdl64e(int beams = 64);
  /// The sensor of a profile: its lasers, range limits, sweep period,
  /// firing positions, range noise and, with ego_body kitti, KITTI's car.
  /// ConfigError for a sweep other than the simulator's (clockwise from
  /// behind, azimuth 180 deg).
  static LidarModel from_profile(const SensorProfile& profile);
  /// KITTI's recording car seen from its roof-mounted HDL-64E (1.73 m above
  /// the road): a box for the body below the belt line (0.93 m above the
  /// road, from 2.03 m ahead of the sensor to 2.39 m behind it, 1.82 m wide)
  /// and one for the roof (1.45 m, 0.84 m behind to 0.30 m ahead, 0.9 m
  /// wide). Fitted to KITTI 00's scans (frames 0-8): straight ahead no return
  /// comes from beams steeper than -21.5 deg (the hood), straight behind
  /// none steeper than -18.5 deg, 40 deg off the rear about half of the
  /// beams below -19.5 deg return, and to the sides every beam reaches the road.
  static std::vector<Eigen::AlignedBox3d> kitti_ego_body();
  /// True when a ray from the sensor along `direction` (sensor frame) meets the ego body.
  [[nodiscard]] bool hits_ego_body(const Eigen::Vector3d& direction) const;
  [[nodiscard]] int beams() const { return static_cast<int>(elevation_deg.size()); }
  /// Azimuth [rad] and time fraction within the sweep of column c.
  [[nodiscard]] double column_azimuth(int column) const;
  [[nodiscard]] double column_fraction(int column) const;
};

/// One sweep: sensor poses at sweep start and at the start of the next sweep
/// (T_W<-L), the world times of both, and the noise seed.
struct SweepSpec {
  Pose start = Pose::Identity();
  Pose end = Pose::Identity();
  /// Poses at evenly spaced instants from start (first) to end (last), for
  /// motion that is not linear within a sweep (the handheld walk): a column's
  /// pose interpolates between the two around its instant. Empty: linear
  /// from start to end.
  std::vector<Pose> knots;
  double time_start = 0;
  double time_end = 0.1;
  std::uint64_t seed = 0;
  bool skew = true;  ///< false: every column at `start` and `time_start`
};

/// A simulated scan with the range-image position of every point.
struct SimulatedScan {
  /// Ground-truth labels; each point in the sensor frame at its own column's
  /// instant (motion-distorted like real data; exact at sweep start).
  LabelledCloud cloud;
  std::vector<std::uint16_t> ring;  ///< beam index (0 = top)
  std::vector<std::uint16_t> column;
  std::vector<float> range;         ///< measured range [m]
  /// Largest vertical distance [m] between the pose and where the sensor
  /// rode on the ground (World::sensor_origin); ~0 for consistent trajectories.
  float sensor_offset = 0;
};

/// Sensor pose T_W<-L when column `column` fires (what simulate_scan uses).
Pose column_pose(const LidarModel& lidar, const SweepSpec& sweep, int column);

/// The points of a scan in the world frame, each moved with its own column's
/// pose: an exact de-skew with the true motion (for tests and ground truth).
std::vector<Eigen::Vector3d> points_in_world(const SimulatedScan& scan, const LidarModel& lidar, const SweepSpec& sweep);

/// The sensor-frame geometry of a sweep's rays, the same in every sweep:
/// beam elevations, column azimuths and the rays that the car's own body
/// stops. Computed once per LiDAR instead of once per scan.
struct SweepRays {
  /// `mount`: the sensor's orientation on the vehicle (R_vehicle<-sensor),
  /// which turns the rays against the car body the lidar model holds.
  explicit SweepRays(const LidarModel& lidar, const Eigen::Matrix3d& mount = Eigen::Matrix3d::Identity());
  std::vector<double> sin_el, cos_el;  ///< per beam
  std::vector<double> cos_az, sin_az;  ///< per column (LidarModel::column_azimuth)
  std::vector<std::uint8_t> blocked;   ///< beam-major, beams x columns: 1 = the ego body stops the ray
  int columns = 0;

  /// Unit direction of ray (beam, column) in the sensor frame (x forward, z up).
  [[nodiscard]] Eigen::Vector3d direction(int beam, int column) const {
    const auto b = static_cast<std::size_t>(beam), c = static_cast<std::size_t>(column);
    return {cos_el[b] * cos_az[c], cos_el[b] * sin_az[c], sin_el[b]};
  }
  [[nodiscard]] bool is_blocked(int beam, int column) const {
    return blocked[static_cast<std::size_t>(beam) * static_cast<std::size_t>(columns) + static_cast<std::size_t>(column)] != 0;
  }
};

/// Ray casts one sweep (columns in parallel; the output does not depend on
/// the number of threads). `rays` must come from the same `lidar`.
SimulatedScan simulate_scan(const World& world, const LidarModel& lidar, const SweepRays& rays, const SweepSpec& sweep);
/// The same, computing the ray table on the way (one-off scans).
SimulatedScan simulate_scan(const World& world, const LidarModel& lidar, const SweepSpec& sweep);

}  // namespace saloam
