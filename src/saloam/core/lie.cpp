#include "saloam/core/lie.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace saloam {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

namespace {
/// Rodrigues' formula for a unit axis, given the sine and cosine of the
/// angle: the arithmetic of Eigen::AngleAxis::toRotationMatrix, so that
/// se3_exp can share one sine and cosine between rotation and Jacobian.
Eigen::Matrix3d rotation_from_axis_angle(const Eigen::Vector3d& axis, double sin_angle, double cos_angle) {
  const Eigen::Vector3d sin_axis = sin_angle * axis;
  const Eigen::Vector3d cos1_axis = (1.0 - cos_angle) * axis;
  Eigen::Matrix3d R;
  double tmp = cos1_axis.x() * axis.y();
  R(0, 1) = tmp - sin_axis.z();
  R(1, 0) = tmp + sin_axis.z();
  tmp = cos1_axis.x() * axis.z();
  R(0, 2) = tmp + sin_axis.y();
  R(2, 0) = tmp - sin_axis.y();
  tmp = cos1_axis.y() * axis.z();
  R(1, 2) = tmp - sin_axis.x();
  R(2, 1) = tmp + sin_axis.x();
  R.diagonal() = cos1_axis.cwiseProduct(axis).array() + cos_angle;
  return R;
}
}  // namespace

Eigen::Matrix3d so3_exp(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  if (theta < 1e-10) {
    return orthonormalize(Eigen::Matrix3d::Identity() + skew(phi));
  }
  return rotation_from_axis_angle(phi / theta, std::sin(theta), std::cos(theta));
}

Eigen::Vector3d so3_log(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(Eigen::Quaterniond(R).normalized());
  double angle = aa.angle();
  Eigen::Vector3d axis = aa.axis();
  if (angle > M_PI) {  // Eigen may return angles in (pi, 2 pi)
    angle = 2.0 * M_PI - angle;
    axis = -axis;
  }
  return axis * angle;
}

namespace {
// Left Jacobian of SO(3) and its inverse, used to couple rotation and translation.
// Below this angle the Jacobians use their series.
constexpr double kSeriesAngle = 1e-6;

/// The left Jacobian for theta = |phi| >= kSeriesAngle, given sin and cos of theta.
Eigen::Matrix3d so3_left_jacobian(const Eigen::Vector3d& phi, double theta, double sin_theta, double cos_theta) {
  const Eigen::Matrix3d K = skew(phi);
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() + (1.0 - cos_theta) / t2 * K + (theta - sin_theta) / (t2 * theta) * K * K;
}

Eigen::Matrix3d so3_left_jacobian(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  if (theta < kSeriesAngle) {
    const Eigen::Matrix3d K = skew(phi);
    return Eigen::Matrix3d::Identity() + 0.5 * K + K * K / 6.0;
  }
  return so3_left_jacobian(phi, theta, std::sin(theta), std::cos(theta));
}

Eigen::Matrix3d so3_left_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (theta < kSeriesAngle) return Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 12.0;
  const double half = 0.5 * theta;
  const double cot_half = std::cos(half) / std::sin(half);
  return Eigen::Matrix3d::Identity() - 0.5 * K +
         (1.0 - half * cot_half) / (theta * theta) * K * K;
}
}  // namespace

Pose se3_exp(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d phi = xi.tail<3>();
  Pose T = Pose::Identity();
  const double theta = phi.norm();
  if (theta < kSeriesAngle) {
    T.linear() = so3_exp(phi);
    T.translation() = so3_left_jacobian(phi) * rho;
    return T;
  }
  // One sine and cosine for both (de-skewing calls this for every point).
  const double sin_theta = std::sin(theta), cos_theta = std::cos(theta);
  T.linear() = rotation_from_axis_angle(phi / theta, sin_theta, cos_theta);
  T.translation() = so3_left_jacobian(phi, theta, sin_theta, cos_theta) * rho;
  return T;
}

Vector6d se3_log(const Pose& T) {
  Vector6d xi;
  const Eigen::Vector3d phi = so3_log(T.linear());
  xi.head<3>() = so3_left_jacobian_inverse(phi) * T.translation();
  xi.tail<3>() = phi;
  return xi;
}

Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& R) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0.0) U.col(2) *= -1.0;
  return U * V.transpose();
}

double orthonormality_error(const Eigen::Matrix3d& R) {
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
}

Pose orthonormalized(const Pose& T) {
  Pose out = T;
  out.linear() = orthonormalize(T.linear());
  out.makeAffine();
  return out;
}

Pose interpolate(const Pose& a, const Pose& b, double s) {
  // Rotation by slerp, translation linearly: the motion model of a spinning
  // LiDAR over one sweep, and what trajectory interpolation conventionally uses.
  const Eigen::Quaterniond qa(a.linear());
  const Eigen::Quaterniond qb(b.linear());
  Pose out = Pose::Identity();
  out.linear() = qa.slerp(s, qb).normalized().toRotationMatrix();
  out.translation() = (1.0 - s) * a.translation() + s * b.translation();
  return out;
}

double rotation_angle(const Pose& T) {
  // Clamped acos of (trace - 1) / 2, as in the KITTI devkit.
  const double c = std::clamp(0.5 * (T.linear().trace() - 1.0), -1.0, 1.0);
  return std::acos(c);
}

Pose pose_from_3x4(const double* v) {
  Pose T = Pose::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = v[r * 4 + c];
    T.translation()(r) = v[r * 4 + 3];
  }
  return T;
}

void pose_to_3x4(const Pose& T, double* v) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) v[r * 4 + c] = T.linear()(r, c);
    v[r * 4 + 3] = T.translation()(r);
  }
}

Eigen::Matrix3d rotation_from_rpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Matrix3d rotation_from_rpy_deg(const Eigen::Vector3d& rpy_deg) {
  const Eigen::Vector3d r = rpy_deg * (M_PI / 180.0);
  return rotation_from_rpy(r.x(), r.y(), r.z());
}

}  // namespace saloam
