#pragma once
// IMU pre-integration between two instants i and j (Forster, Carlone,
// Dellaert and Scaramuzza, "On-Manifold Preintegration for Real-Time
// Visual-Inertial Odometry", IEEE T-RO 2017): the body frame's rotation,
// velocity and position increments from the samples, without gravity and
// the initial velocity, so that for any world frame w with gravity g
// (Eq. 33):
//   R_j = R_i dR
//   v_j = v_i + g dt + R_i dv
//   p_j = p_i + v_i dt + 1/2 g dt^2 + R_i dp
// Also their first-order Jacobians with respect to the biases (Appendix B,
// so a new bias estimate corrects the increments without integrating
// again) and the covariance of the increments' errors (dphi, dv, dp) from
// the sensor's white noise (Eqs. 62-63).
//
// Frames and units: samples in the body (IMU) frame; [s], [m/s^2], [rad/s].

#include <span>

#include <Eigen/Core>

#include "saloam/imu/imu_noise.hpp"
#include "saloam/imu/imu_sample.hpp"

namespace saloam {

/// SO(3)'s right Jacobian J_r(phi) (Forster, Eq. 8).
Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi);

/// A body frame's state in a world frame: orientation R_w<-b, velocity and position [m/s, m].
struct NavState {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

class ImuPreintegration {
 public:
  /// Increments with the biases (body frame) subtracted from every sample.
  explicit ImuPreintegration(const Eigen::Vector3d& gyro_bias = Eigen::Vector3d::Zero(),
                             const Eigen::Vector3d& accel_bias = Eigen::Vector3d::Zero());

  /// Adds a measurement held for dt [s] (Eqs. 24-26 for one step). `noise`,
  /// when given, propagates the covariance (its densities, discretised over dt).
  void integrate(const Eigen::Vector3d& acceleration, const Eigen::Vector3d& angular_velocity, double dt,
                 const ImuNoise* noise = nullptr);

  [[nodiscard]] double duration() const { return duration_; }
  [[nodiscard]] const Eigen::Matrix3d& delta_rotation() const { return delta_R_; }
  [[nodiscard]] const Eigen::Vector3d& delta_velocity() const { return delta_v_; }
  [[nodiscard]] const Eigen::Vector3d& delta_position() const { return delta_p_; }
  /// Covariance of (dphi, dv, dp), rotation error on the right: dR_true = dR Exp(dphi).
  [[nodiscard]] const Eigen::Matrix<double, 9, 9>& covariance() const { return covariance_; }

  /// The increments for other biases, to first order (Eq. 44).
  [[nodiscard]] Eigen::Matrix3d delta_rotation(const Eigen::Vector3d& gyro_bias) const;
  [[nodiscard]] Eigen::Vector3d delta_velocity(const Eigen::Vector3d& gyro_bias, const Eigen::Vector3d& accel_bias) const;
  [[nodiscard]] Eigen::Vector3d delta_position(const Eigen::Vector3d& gyro_bias, const Eigen::Vector3d& accel_bias) const;

  /// State j from state i under gravity g (world frame), with the biases integrated.
  [[nodiscard]] NavState predict(const NavState& i, const Eigen::Vector3d& gravity) const;

 private:
  Eigen::Vector3d gyro_bias_, accel_bias_;
  double duration_ = 0.0;
  Eigen::Matrix3d delta_R_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d delta_v_ = Eigen::Vector3d::Zero(), delta_p_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d dR_dbg_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d dv_dbg_ = Eigen::Matrix3d::Zero(), dv_dba_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d dp_dbg_ = Eigen::Matrix3d::Zero(), dp_dba_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 9, 9> covariance_ = Eigen::Matrix<double, 9, 9>::Zero();
};

/// Pre-integrates the samples over [t0, t1]: between consecutive samples the
/// measurement is taken as linear in time and each interval integrated at its
/// midpoint value (second order in the step); before the first and after the
/// last sample it is held. The samples must be in time order and cover
/// [t0, t1] (std::invalid_argument otherwise: the caller says which stream).
ImuPreintegration preintegrate(std::span<const ImuSample> samples, double t0, double t1,
                               const Eigen::Vector3d& gyro_bias = Eigen::Vector3d::Zero(),
                               const Eigen::Vector3d& accel_bias = Eigen::Vector3d::Zero(),
                               const ImuNoise* noise = nullptr);

}  // namespace saloam
