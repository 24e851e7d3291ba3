#include "saloam/odometry/residuals.hpp"

#include <Eigen/Eigenvalues>

#include "saloam/core/semantic_classes.hpp"

namespace saloam {

namespace {
struct Moments {
  Eigen::Vector3d mean;
  Eigen::Matrix3d covariance;
};
Moments moments(std::span<const Eigen::Vector3d> points) {
  Moments m{Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero()};
  for (const auto& p : points) m.mean += p;
  m.mean /= static_cast<double>(points.size());
  // The lower triangle, mirrored: d_a d_b = d_b d_a, so the matrix is the
  // same as summing the full outer products, for two thirds of the work.
  for (const auto& p : points) {
    const Eigen::Vector3d d = p - m.mean;
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b <= a; ++b) m.covariance(a, b) += d[a] * d[b];
    }
  }
  m.covariance /= static_cast<double>(points.size());
  m.covariance(0, 1) = m.covariance(1, 0);
  m.covariance(0, 2) = m.covariance(2, 0);
  m.covariance(1, 2) = m.covariance(2, 1);
  return m;
}
}  // namespace

std::optional<Line> fit_line(std::span<const Eigen::Vector3d> points, double min_ratio) {
  if (points.size() < 2) return std::nullopt;
  const Moments m = moments(points);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(m.covariance);  // closed form for 3x3: several times faster
  const Eigen::Vector3d& values = eig.eigenvalues();  // ascending
  if (values(2) <= 1e-12 || values(2) < min_ratio * values(1)) return std::nullopt;
  return Line{m.mean, eig.eigenvectors().col(2).normalized()};
}

std::optional<Plane> fit_plane(std::span<const Eigen::Vector3d> points, double max_distance) {
  if (points.size() < 3) return std::nullopt;
  const Moments m = moments(points);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(m.covariance);
  const Eigen::Vector3d& values = eig.eigenvalues();
  // Collinear neighbours do not define a plane.
  if (values(1) < 1e-3 * values(2) || values(2) <= 1e-12) return std::nullopt;
  const Eigen::Vector3d normal = eig.eigenvectors().col(0).normalized();
  for (const auto& p : points) {
    if (std::abs(normal.dot(p - m.mean)) > max_distance) return std::nullopt;
  }
  return Plane{m.mean, normal};
}

PlaneOrientation plane_orientation(std::uint16_t raw_class) {
  const std::uint16_t c = static_class(raw_class);
  if (is_ground(c)) return PlaneOrientation::kHorizontal;
  if (c == cls::kBuilding || c == cls::kFence) return PlaneOrientation::kVertical;
  return PlaneOrientation::kAny;
}

bool plane_satisfies_constraint(const Eigen::Vector3d& normal, PlaneOrientation orientation, double sigma,
                                const Eigen::Vector3d& up_direction) {
  const double up = std::abs(normal.dot(up_direction));
  switch (orientation) {
    case PlaneOrientation::kHorizontal: return up >= 1.0 - sigma;
    case PlaneOrientation::kVertical: return up <= sigma;
    case PlaneOrientation::kAny: return true;
  }
  return true;
}

double point_to_plane_residual(const Pose& T, const Eigen::Vector3d& p, const Plane& plane,
                               Eigen::Matrix<double, 1, 6>* jacobian) {
  const Eigen::Vector3d q = T * p;
  if (jacobian) {
    const Eigen::RowVector3d nR = plane.normal.transpose() * T.linear();
    jacobian->leftCols<3>() = nR;
    jacobian->rightCols<3>() = -nR * skew(p);
  }
  return plane.normal.dot(q - plane.point);
}

Eigen::Vector3d point_to_line_residual(const Pose& T, const Eigen::Vector3d& p, const Line& line,
                                       Eigen::Matrix<double, 3, 6>* jacobian) {
  const Eigen::Vector3d q = T * p;
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - line.direction * line.direction.transpose();
  if (jacobian) {
    const Eigen::Matrix3d PR = P * T.linear();
    jacobian->leftCols<3>() = PR;
    jacobian->rightCols<3>() = -PR * skew(p);
  }
  return P * (q - line.point);
}

Pose apply_update(const Vector6d& delta, const Pose& T) { return orthonormalized(T * se3_exp(delta)); }

}  // namespace saloam
