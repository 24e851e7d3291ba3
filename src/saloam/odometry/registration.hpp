#pragma once
// Scan-to-local-map registration (paper Sec. III-B, Eq. 2): each edge feature
// is matched to a line and each planar feature to a plane fitted to its
// nearest map neighbours of the same class, and the pose minimises the
// weighted, robustified sum of squared point-to-line and point-to-plane
// distances by Gauss-Newton (Levenberg-Marquardt damped) on SE(3), with a few
// outer rounds that re-associate at the new pose.

#include <array>
#include <cmath>
#include <functional>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/odometry/features.hpp"
#include "saloam/odometry/local_map.hpp"
#include "saloam/odometry/residuals.hpp"

namespace saloam {

/// A residual's weight in the fit (Eq. 2's w^l times the robust kernel): its
/// class's weight times the Huber weight at its distance, the one place that
/// combines them.
struct ClassWeightedHuber {
  const std::array<double, kNumClassIndices>& class_weight;
  double scale;  ///< [m] Huber scale

  double operator()(ClassIndex c, double distance) const { return class_weight[c] * huber_weight(distance, scale); }
};

/// Built from the configuration (odometry.*), which holds the defaults; a
/// default-constructed value is all zeros.
struct RegistrationSettings {
  int edge_neighbours{};                ///< N_ne
  int planar_neighbours{};              ///< N_np
  double max_correspondence_distance{};  ///< [m]
  double robust_kernel_scale{};         ///< [m] Huber scale
  int max_iterations{};
  int outer_iterations{};
  /// An outer round that moved the pose less than this ends the re-association.
  double reassociation_min_translation{};  ///< [m] (0: always all rounds)
  double reassociation_min_rotation{};     ///< [rad]
  /// A scan that started far off (its pose moved by more than 0.1 m or 1 deg
  /// from the initial guess in outer_iterations rounds, as after a fast turn
  /// that the prediction missed) re-associates on while its pose still moves
  /// by the thresholds above, up to this many rounds in all: each round's
  /// neighbours lie within max_correspondence_distance, so an error of many
  /// of them is walked in round by round. <= outer_iterations: never beyond.
  int far_outer_iterations{};
  double plane_normal_tolerance{};         ///< plane constraint: tolerance on |n . up|
  /// A fitted line with |direction . up| below this is matched as the vertical
  /// plane through it (a 1-D residual across it, horizontal); 0: every line
  /// is a line (OdometryConfig::level_line_max_rise).
  double level_line_max_rise{};
  /// Up in the map's frame (unit; odometry/gravity.hpp): what "vertical" and
  /// "horizontal" mean to the plane constraint and the level lines.
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  std::array<double, kNumClassIndices> class_weight{};          ///< w^l
  std::array<PlaneOrientation, kNumClassIndices> orientation{};  ///< plane constraint per class
  bool parallel{};  ///< associate and sum the normal equations with TBB (inside the caller's task arena); same result
  /// [m] a final correspondence closer than this counts as an inlier
  /// (RegistrationResult::inliers). Loop verification sets loop.inlier_distance;
  /// the odometry counts none (0): nothing reads its inliers.
  double inlier_distance{};
  /// Degeneracy (Zhang, Kaess and Singh, "On degeneracy of optimization-based
  /// state estimation problems", ICRA 2016): a direction whose eigenvalue of
  /// the normalised Hessian (normalized_hessian()) is below this is not
  /// constrained by the scene (a corridor along its axis, an open field in
  /// yaw); Gauss-Newton then leaves the pose at the initial guess (the
  /// odometry's constant-velocity prediction) along it and moves it only in
  /// the constrained directions. 0: off (every direction is solved).
  double degeneracy_eigenvalue{};

  /// From the config; without semantics all weights are 1 and no plane constraint applies.
  static RegistrationSettings from_config(const OdometryConfig& config);
};

/// Residuals beyond this many robust kernel scales count as this many in
/// RegistrationResult's per-class residual sums (outliers bounded).
inline constexpr double kResidualClip = 3.0;

struct RegistrationResult {
  Pose pose = Pose::Identity();
  int edge_matches = 0;
  int planar_matches = 0;
  int rejected_by_constraint = 0;  ///< planes dropped by the semantic plane constraint
  int iterations = 0;
  int associations = 0;  ///< association rounds (neighbour search and fit for every feature)
  bool ok = false;  ///< false: too few correspondences, pose = initial guess
  bool converged = false;  ///< the last Gauss-Newton round ended on a negligible step
  /// Eigenvalues of normalized_hessian() at the final fit below
  /// settings.degeneracy_eigenvalue (0 when that is 0): the directions in
  /// which the pose kept the initial guess.
  int degenerate_directions = 0;
  double smallest_eigenvalue = 0;  ///< of normalized_hessian() at the final fit

  // The fit at the final pose over the final correspondences (what loop
  // verification tests and the pose graph weighs):
  /// r of Eq. 2: sum over correspondences of w^l * |residual| [m].
  double loss = 0;
  int inliers = 0;                  ///< correspondences with |residual| < inlier_distance
  double inlier_residual_sum = 0;   ///< [m] sum of |residual| over the inliers
  /// Gauss-Newton Hessian sum of w^l * huber * J^T J for the right perturbation
  /// T * exp([rho; phi]) (sensor frame, translation first): the information
  /// of the pose up to the residuals' noise scale.
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  /// Per matched class: sum of squared residuals, each clipped at
  /// kResidualClip * robust_kernel_scale [m^2], and their degrees of freedom
  /// (2 per point-to-line, 1 per point-to-plane residual): a class's residual
  /// variance is the ratio.
  std::array<double, kNumClassIndices> class_squared_residuals{};
  std::array<double, kNumClassIndices> class_dof{};

  [[nodiscard]] int correspondences() const { return edge_matches + planar_matches; }
  [[nodiscard]] bool degenerate() const { return degenerate_directions > 0; }
  [[nodiscard]] double mean_inlier_residual() const { return inliers > 0 ? inlier_residual_sum / inliers : 0.0; }
};

/// The Hessian per correspondence with the rotation scaled to the
/// displacement it causes at `lever` metres from the sensor (y = (rho,
/// lever * phi)): translation and rotation eigenvalues on one scale, 1 when
/// every residual fully constrains a direction, 0 when none does.
Eigen::Matrix<double, 6, 6> normalized_hessian(const Eigen::Matrix<double, 6, 6>& hessian, int correspondences,
                                               double lever);

/// Registers features (sensor frame) to the map starting from `initial` (T_world<-sensor).
RegistrationResult register_scan(const FeatureCloud& edges, const FeatureCloud& planars,
                                 const SemanticLocalMap& map, const Pose& initial,
                                 const RegistrationSettings& settings);

/// Called between outer rounds with the current pose: may move the scan's
/// points (keeping their number and order), e.g. de-skew them again with the
/// motion that the pose implies; returns whether it did. A refreshed scan is
/// always re-associated, however little the pose moved.
using FeatureRefresh = std::function<bool(const Pose& pose, ScanFeatures& scan)>;

/// As above, with `refresh` run before every re-association.
RegistrationResult register_scan(ScanFeatures& scan, const SemanticLocalMap& map, const Pose& initial,
                                 const RegistrationSettings& settings, const FeatureRefresh& refresh);

}  // namespace saloam
