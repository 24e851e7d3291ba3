#pragma once
// The configuration's odometry.gravity section (core/config.hpp holds the
// rest and its visit_fields list): which way is up for a run.

#include <optional>
#include <vector>

#include <Eigen/Core>

namespace saloam {

/// Which way is up: the direction of gravity in the sensor frame, which
/// every rule meaning "horizontal" or "vertical" uses (the plane constraint,
/// level lines, the ground below which no edges are taken, the place
/// descriptors, the loop guesses). In order of trust: the mount given here,
/// else estimated from the scans (the ground's normal, upright walls, poles
/// and trunks over the first scans, refined as the run goes), else the
/// sensor's z. The outputs' world frame stays the first scan's sensor frame.
/// Between the mount and the scans ranks the sensor's own IMU at rest, when
/// the source has one (an Ouster capture).
struct GravityConfig {
  /// The sensor's orientation on the robot, R_base<-sensor as roll, pitch,
  /// yaw [deg] (R = Rz(yaw) Ry(pitch) Rx(roll), the URDF / ROS convention), as
  /// a `base_link` robot publishes it; the base's z is up. Empty: not given.
  std::vector<double> mount_rpy_deg;
  /// Without a mount: take up from the sensor's own IMU at rest when the
  /// source has one (an Ouster capture's IMU packets).
  bool use_imu = true;
  /// Without a mount (or IMU): estimate up from the scans (true) or take the
  /// sensor's z as up (false).
  bool estimate = true;
  /// Scans are looked at every this many frames to refine the estimate (or,
  /// with a mount, to check it).
  int refine_every_frames = 10;
  /// [deg] A given mount whose up the scans contradict by more than this is
  /// warned about (both directions named); the mount is still used.
  double mount_warning_deg = 8.0;
  /// Up in the first scan's frame from the sensor's own IMU (SourceInfo::imu_up):
  /// set by a run from its source, not a parameter (not in the YAML).
  std::optional<Eigen::Vector3d> imu_up;
};

}  // namespace saloam
