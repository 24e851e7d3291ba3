#include "saloam/imu/preintegration.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "saloam/core/lie.hpp"

namespace saloam {

Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (theta < 1e-5) return Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 6.0;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() - (1.0 - std::cos(theta)) / t2 * K + (theta - std::sin(theta)) / (t2 * theta) * K * K;
}

ImuPreintegration::ImuPreintegration(const Eigen::Vector3d& gyro_bias, const Eigen::Vector3d& accel_bias)
    : gyro_bias_(gyro_bias), accel_bias_(accel_bias) {}

void ImuPreintegration::integrate(const Eigen::Vector3d& acceleration, const Eigen::Vector3d& angular_velocity, double dt,
                                  const ImuNoise* noise) {
  if (!(dt > 0.0)) return;
  const Eigen::Vector3d a = acceleration - accel_bias_;
  const Eigen::Vector3d phi = (angular_velocity - gyro_bias_) * dt;
  const Eigen::Matrix3d step = so3_exp(phi);  // dR_k,k+1
  const Eigen::Matrix3d Jr = so3_right_jacobian(phi);
  const Eigen::Matrix3d Ra = delta_R_ * skew(a);  // dR_k [a]x
  // The covariance first (Eq. 63: A and B at step k).
  if (noise) {
    Eigen::Matrix<double, 9, 9> A = Eigen::Matrix<double, 9, 9>::Identity();
    A.block<3, 3>(0, 0) = step.transpose();
    A.block<3, 3>(3, 0) = -Ra * dt;
    A.block<3, 3>(6, 0) = -0.5 * Ra * dt * dt;
    A.block<3, 3>(6, 3) = Eigen::Matrix3d::Identity() * dt;
    Eigen::Matrix<double, 9, 3> Bg = Eigen::Matrix<double, 9, 3>::Zero(), Ba = Eigen::Matrix<double, 9, 3>::Zero();
    Bg.block<3, 3>(0, 0) = Jr * dt;
    Ba.block<3, 3>(3, 0) = delta_R_ * dt;
    Ba.block<3, 3>(6, 0) = 0.5 * delta_R_ * dt * dt;
    // White noise of density s seen through a sample held for dt: variance s^2 / dt.
    const double gyro_var = noise->gyro_noise_density * noise->gyro_noise_density / dt;
    const double accel_var = noise->accel_noise_density * noise->accel_noise_density / dt;
    covariance_ = A * covariance_ * A.transpose() + gyro_var * Bg * Bg.transpose() + accel_var * Ba * Ba.transpose();
  }
  // Bias Jacobians (Appendix B), position before velocity before rotation:
  // each uses the others' values at step k.
  dp_dba_ += dv_dba_ * dt - 0.5 * delta_R_ * dt * dt;
  dp_dbg_ += dv_dbg_ * dt - 0.5 * Ra * dR_dbg_ * dt * dt;
  dv_dba_ -= delta_R_ * dt;
  dv_dbg_ -= Ra * dR_dbg_ * dt;
  dR_dbg_ = step.transpose() * dR_dbg_ - Jr * dt;
  // The increments (Eq. 26).
  delta_p_ += delta_v_ * dt + 0.5 * delta_R_ * a * dt * dt;
  delta_v_ += delta_R_ * a * dt;
  delta_R_ = orthonormalize(delta_R_ * step);
  duration_ += dt;
}

Eigen::Matrix3d ImuPreintegration::delta_rotation(const Eigen::Vector3d& gyro_bias) const {
  return orthonormalize(delta_R_ * so3_exp(dR_dbg_ * (gyro_bias - gyro_bias_)));
}

Eigen::Vector3d ImuPreintegration::delta_velocity(const Eigen::Vector3d& gyro_bias, const Eigen::Vector3d& accel_bias) const {
  return delta_v_ + dv_dbg_ * (gyro_bias - gyro_bias_) + dv_dba_ * (accel_bias - accel_bias_);
}

Eigen::Vector3d ImuPreintegration::delta_position(const Eigen::Vector3d& gyro_bias, const Eigen::Vector3d& accel_bias) const {
  return delta_p_ + dp_dbg_ * (gyro_bias - gyro_bias_) + dp_dba_ * (accel_bias - accel_bias_);
}

NavState ImuPreintegration::predict(const NavState& i, const Eigen::Vector3d& gravity) const {
  const double dt = duration_;
  NavState j;
  j.rotation = orthonormalize(i.rotation * delta_R_);
  j.velocity = i.velocity + gravity * dt + i.rotation * delta_v_;
  j.position = i.position + i.velocity * dt + 0.5 * gravity * dt * dt + i.rotation * delta_p_;
  return j;
}

namespace {
// The measurement at time t, linear between the samples around it, held
// beyond the first and the last.
ImuSample measurement_at(std::span<const ImuSample> samples, double t) {
  const auto after = std::upper_bound(samples.begin(), samples.end(), t,
                                      [](double time, const ImuSample& s) { return time < s.time; });
  if (after == samples.begin()) return samples.front();
  if (after == samples.end()) return samples.back();
  const ImuSample& a = *(after - 1);
  const ImuSample& b = *after;
  const double f = b.time > a.time ? (t - a.time) / (b.time - a.time) : 0.0;
  return {t, a.acceleration + f * (b.acceleration - a.acceleration),
          a.angular_velocity + f * (b.angular_velocity - a.angular_velocity)};
}
}  // namespace

ImuPreintegration preintegrate(std::span<const ImuSample> samples, double t0, double t1, const Eigen::Vector3d& gyro_bias,
                               const Eigen::Vector3d& accel_bias, const ImuNoise* noise) {
  if (samples.empty() || samples.front().time > t0 || samples.back().time < t1 || t1 < t0) {
    throw std::invalid_argument("IMU samples do not cover the interval to integrate");
  }
  ImuPreintegration result(gyro_bias, accel_bias);
  // The interval's breakpoints: t0, every sample time inside, t1.
  double t = t0;
  ImuSample at_t = measurement_at(samples, t0);
  auto next = std::upper_bound(samples.begin(), samples.end(), t0,
                               [](double time, const ImuSample& s) { return time < s.time; });
  while (t < t1) {
    const double t_next = (next != samples.end() && next->time < t1) ? next->time : t1;
    const ImuSample at_next = measurement_at(samples, t_next);
    result.integrate(0.5 * (at_t.acceleration + at_next.acceleration), 0.5 * (at_t.angular_velocity + at_next.angular_velocity),
                     t_next - t, noise);
    t = t_next;
    at_t = at_next;
    if (next != samples.end() && next->time <= t) ++next;
  }
  return result;
}

}  // namespace saloam
