#pragma once
// Geometric correspondences and residuals of the scan-to-map registration
// (paper Sec. III-B, Eq. 2): lines and planes fitted to map neighbours, the
// semantic plane constraint, and point-to-line / point-to-plane residuals
// with their analytic Jacobians.
//
// Pose perturbation convention: T <- T * exp(delta) with delta = [rho; phi]
// (right, sensor frame), so for q = T p: dq/d delta = R [ I | -[p]x ].
// Perturbing in the sensor frame keeps the problem equally well conditioned
// wherever the sensor is: a left (world-frame) rotation turns about the world
// origin, hundreds of metres away after a while, which couples rotation and
// translation through that lever arm; the damped solver then converged too
// slowly to follow sharp turns (simulated KITTI 00, ~370 m from the origin).

#include <cmath>
#include <cstdint>
#include <optional>
#include <span>

#include <Eigen/Core>

#include "saloam/core/lie.hpp"
#include "saloam/core/types.hpp"

namespace saloam {

struct Line {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();      ///< centroid of the neighbours
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< unit
};

struct Plane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   ///< centroid of the neighbours
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit
};

/// PCA line through the points; nullopt unless line-like: the largest
/// eigenvalue of the covariance must exceed `min_ratio` times the second.
std::optional<Line> fit_line(std::span<const Eigen::Vector3d> points, double min_ratio = 3.0);

/// PCA plane through the points; nullopt unless planar: every point within
/// `max_distance` [m] of the plane and the points not collinear.
std::optional<Plane> fit_plane(std::span<const Eigen::Vector3d> points, double max_distance = 0.2);

/// Which orientation the plane constraint demands for a class.
enum class PlaneOrientation { kAny, kHorizontal /* ground: normal near vertical */, kVertical /* building, fence */ };

/// The constraint for a raw SemanticKITTI class: ground classes (road,
/// sidewalk, parking, terrain, other-ground, lane-marking) need a near-vertical
/// normal, building and fence a near-horizontal one, others anything.
PlaneOrientation plane_orientation(std::uint16_t raw_class);

/// The plane constraint with tolerance sigma on |n . up| (up: the unit
/// direction against gravity in the map's frame, odometry/gravity.hpp):
/// horizontal planes need |n . up| >= 1 - sigma, vertical ones |n . up| <= sigma.
bool plane_satisfies_constraint(const Eigen::Vector3d& normal, PlaneOrientation orientation, double sigma,
                                const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

/// Point-to-plane residual n . (T p - c) and its 1x6 Jacobian w.r.t. delta.
double point_to_plane_residual(const Pose& T, const Eigen::Vector3d& p, const Plane& plane,
                               Eigen::Matrix<double, 1, 6>* jacobian = nullptr);

/// Point-to-line residual (I - d d^T)(T p - c): a 3-vector whose norm is the
/// distance to the line, and its 3x6 Jacobian w.r.t. delta.
Eigen::Vector3d point_to_line_residual(const Pose& T, const Eigen::Vector3d& p, const Line& line,
                                       Eigen::Matrix<double, 3, 6>* jacobian = nullptr);

/// The residual kinds of the registration, one type each (small_gicp's
/// factors): the geometry a feature was matched to, its residual with the
/// Jacobian, the distance the robust kernel sees, the constraints it adds
/// (dof) and its terms of Gauss-Newton's normal equations.
///
/// An edge feature against a line (Eq. 2's point-to-line distance).
struct PointToLine {
  using Residual = Eigen::Vector3d;
  using Jacobian = Eigen::Matrix<double, 3, 6>;
  static constexpr double kDof = 2.0;  ///< across the line, both ways

  Line line;

  Residual residual(const Pose& T, const Eigen::Vector3d& p, Jacobian* jacobian) const {
    return point_to_line_residual(T, p, line, jacobian);
  }
  static double distance(const Residual& r) { return r.norm(); }
  /// H += w J^T J, g += w J^T r.
  static void add_normal_terms(double w, const Jacobian& J, const Residual& r, Eigen::Matrix<double, 6, 6>& H, Vector6d& g) {
    H.noalias() += w * J.transpose() * J;
    g.noalias() += w * J.transpose() * r;
  }
};

/// A planar feature against a plane (Eq. 2's point-to-plane distance), or an
/// edge feature against the vertical plane through a level line.
struct PointToPlane {
  using Residual = double;
  using Jacobian = Eigen::Matrix<double, 1, 6>;
  static constexpr double kDof = 1.0;  ///< along the normal

  Plane plane;

  Residual residual(const Pose& T, const Eigen::Vector3d& p, Jacobian* jacobian) const {
    return point_to_plane_residual(T, p, plane, jacobian);
  }
  static double distance(Residual r) { return std::abs(r); }
  /// H += w J^T J, g += w r J^T.
  static void add_normal_terms(double w, const Jacobian& J, Residual r, Eigen::Matrix<double, 6, 6>& H, Vector6d& g) {
    H.noalias() += w * J.transpose() * J;
    g.noalias() += (w * r) * J.transpose();
  }
};

/// The Huber kernel's weight at `distance` with scale `k`: 1 within k, k / |r| beyond.
inline double huber_weight(double distance, double k) {
  const double a = std::abs(distance);
  return a <= k ? 1.0 : k / a;
}

/// Applies the right update T <- T exp(delta) and re-orthonormalizes the rotation.
Pose apply_update(const Vector6d& delta, const Pose& T);

}  // namespace saloam
