#pragma once
// SE(3)/SO(3) helpers: exponential and logarithm maps, projection back onto
// the manifold, and interpolation. Tangent vectors are ordered
// [translation; rotation] (rho, phi), as in most LiDAR odometry code.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "saloam/core/types.hpp"

namespace saloam {

using Vector6d = Eigen::Matrix<double, 6, 1>;

/// Skew-symmetric matrix [v]x such that [v]x * w = v.cross(w).
Eigen::Matrix3d skew(const Eigen::Vector3d& v);

/// SO(3) exponential (Rodrigues), exact for small angles too.
Eigen::Matrix3d so3_exp(const Eigen::Vector3d& phi);
/// SO(3) logarithm, returns the rotation vector (angle in [0, pi]).
Eigen::Vector3d so3_log(const Eigen::Matrix3d& R);

/// SE(3) exponential of xi = [rho; phi].
Pose se3_exp(const Vector6d& xi);
/// SE(3) logarithm, inverse of se3_exp.
Vector6d se3_log(const Pose& T);

/// Nearest rotation matrix (SVD projection, det = +1).
Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& R);
/// ||R^T R - I|| (Frobenius norm): 0 for a rotation matrix. KITTI's calib
/// `Tr` deviates by about 1e-4 (printed digits), a scaled or sheared matrix by
/// far more.
double orthonormality_error(const Eigen::Matrix3d& R);
/// The largest orthonormality_error() accepted for a rotation read from a file.
inline constexpr double kRotationTolerance = 1e-3;

/// Returns T with its rotation re-orthonormalized. Apply after every
/// composition chain: accumulated float error otherwise drifts off SO(3).
Pose orthonormalized(const Pose& T);

/// Interpolation between a (s = 0) and b (s = 1): slerp on the rotation,
/// linear on the translation.
Pose interpolate(const Pose& a, const Pose& b, double s);

/// Rotation angle of T in radians, in [0, pi].
double rotation_angle(const Pose& T);

/// R = Rz(yaw) Ry(pitch) Rx(roll) [rad]: the URDF / ROS `rpy` convention
/// (roll about x, then pitch about y, then yaw about z, all fixed axes).
Eigen::Matrix3d rotation_from_rpy(double roll, double pitch, double yaw);
/// The same from [roll, pitch, yaw] in degrees.
Eigen::Matrix3d rotation_from_rpy_deg(const Eigen::Vector3d& rpy_deg);

/// Builds a pose from a row-major 3x4 [R | t] array (KITTI text layout).
Pose pose_from_3x4(const double* values12);
/// Writes the row-major 3x4 block of T into values12.
void pose_to_3x4(const Pose& T, double* values12);

}  // namespace saloam
