#pragma once
// One inertial measurement, and the gravity constant every IMU reader shares.
// Frames and units: a sample is in the frame its reader says (its IMU's own,
// or the LiDAR frame it was rotated into); time [s] on the clock of the
// scans' times; specific force [m/s^2] (at rest it points up, 1 g long),
// angular velocity [rad/s].

#include <Eigen/Core>

namespace saloam {

inline constexpr double kStandardGravity = 9.80665;  ///< [m/s^2] 1 g (CGPM 1901)

struct ImuSample {
  double time = 0.0;                                           ///< [s]
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();      ///< [m/s^2] specific force
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< [rad/s]
};

}  // namespace saloam
