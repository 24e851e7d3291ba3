#include "saloam/odometry/registration.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/core/parallel.hpp"

namespace saloam {

namespace {
// Rounds in all for a scan far from its optimum (far_outer_iterations): a
// handheld sensor's look-around, missed by up to ~20 deg, needs ~15
// (docs/odometry.md, "Fast turns"). Not in OdometryConfig yet.
constexpr int kFarOuterIterations = 20;
// A scan whose pose has moved this far from its initial guess over the
// first outer_iterations rounds started far off: a vehicle's constant-velocity
// prediction misses by ~1 cm and ~0.1 deg, a hand's look-around by degrees.
constexpr double kFarTranslation = 0.1;          // [m]
constexpr double kFarRotation = M_PI / 180.0;    // [rad]
}  // namespace

RegistrationSettings RegistrationSettings::from_config(const OdometryConfig& config) {
  RegistrationSettings s;
  s.edge_neighbours = config.edge_neighbours;
  s.planar_neighbours = config.planar_neighbours;
  s.max_correspondence_distance = config.max_correspondence_distance;
  s.robust_kernel_scale = config.robust_kernel_scale;
  s.max_iterations = config.max_iterations;
  s.outer_iterations = config.outer_iterations;
  s.far_outer_iterations = kFarOuterIterations;
  s.reassociation_min_translation = config.reassociation_min_translation;
  s.reassociation_min_rotation = config.reassociation_min_rotation_deg * M_PI / 180.0;
  s.plane_normal_tolerance = config.plane_normal_tolerance;
  s.level_line_max_rise = config.level_line_max_rise;
  s.class_weight = class_weights(config);
  for (int c = 0; c < kNumClassIndices; ++c) {
    s.orientation[c] = config.use_semantics
                           ? plane_orientation(from_learning_class(static_cast<std::uint8_t>(c)))
                           : PlaneOrientation::kAny;
  }
  s.parallel = config.threads != 1;
  s.degeneracy_eigenvalue = config.degeneracy_eigenvalue;
  return s;
}

Eigen::Matrix<double, 6, 6> normalized_hessian(const Eigen::Matrix<double, 6, 6>& hessian, int correspondences,
                                               double lever) {
  Vector6d inverse_scale;
  inverse_scale << 1, 1, 1, 1 / lever, 1 / lever, 1 / lever;
  return inverse_scale.asDiagonal() * hessian * inverse_scale.asDiagonal() / std::max(1, correspondences);
}

namespace {

constexpr int kMaxNeighbours = kMaxFitNeighbours;

// What a feature was matched to: nothing, a line (an edge feature) or a
// plane (a planar feature's, or the vertical plane through a level line,
// RegistrationSettings::level_line_max_rise). The kind is chosen once, here;
// the fit visits the residual type.
struct Match {
  std::variant<std::monostate, PointToLine, PointToPlane> fit;
  bool rejected_by_constraint = false;  ///< a plane the semantic plane constraint refused
  [[nodiscard]] bool matched() const { return !std::holds_alternative<std::monostate>(fit); }
};

// Gathers the k nearest neighbours of q among the map points of class c;
// false unless all k lie within the correspondence distance.
bool gather(const NeighbourGrid& grid, const Eigen::Vector3d& q, ClassIndex c, int k, double max_distance,
            std::array<Eigen::Vector3d, kMaxNeighbours>& out) {
  std::array<double, kMaxNeighbours> d2{};
  return grid.nearest(q, c, k, max_distance, out.data(), d2.data()) == k;
}

// The residuals of a scan form one index space, the edges [0, edges) then the
// planar points; sums over it go in blocks of this many residuals
// (sum_in_blocks), so they are the same with any number of threads.
constexpr std::size_t kResidualBlock = 512;

// Calls on_residual(fit, point, class) for residual i of that index space when
// its feature is matched, `fit` of its residual type (PointToLine or
// PointToPlane).
template <class OnResidual>
void visit_residual(std::size_t i, const FeatureCloud& edges, const FeatureCloud& planars,
                    const std::vector<Match>& edge_matches, const std::vector<Match>& plane_matches,
                    OnResidual&& on_residual) {
  const bool edge = i < edge_matches.size();
  const std::size_t j = edge ? i : i - edge_matches.size();
  const FeatureCloud& cloud = edge ? edges : planars;
  std::visit(
      [&](const auto& fit) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(fit)>, std::monostate>) {
          on_residual(fit, cloud.points[j], cloud.classes[j]);
        }
      },
      (edge ? edge_matches : plane_matches)[j].fit);
}

// The fit's sums over the matched features (RegistrationResult's fields).
struct FitSums {
  double loss = 0;
  int inliers = 0;
  double inlier_residual_sum = 0;
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  std::array<double, kNumClassIndices> class_squared_residuals{};
  std::array<double, kNumClassIndices> class_dof{};

  FitSums& operator+=(const FitSums& o) {
    loss += o.loss;
    inliers += o.inliers;
    inlier_residual_sum += o.inlier_residual_sum;
    hessian += o.hessian;
    for (int c = 0; c < kNumClassIndices; ++c) {
      class_squared_residuals[c] += o.class_squared_residuals[c];
      class_dof[c] += o.class_dof[c];
    }
    return *this;
  }
};

// Loss, inliers and Hessian of the matched features at pose T (no new association).
void evaluate_fit(const FeatureCloud& edges, const FeatureCloud& planars, const std::vector<Match>& edge_matches,
                  const std::vector<Match>& plane_matches, const Pose& T, const RegistrationSettings& settings,
                  RegistrationResult& result) {
  const ClassWeightedHuber weight{settings.class_weight, settings.robust_kernel_scale};
  const double clip = kResidualClip * settings.robust_kernel_scale;
  const auto term = [&](std::size_t i, FitSums& sum) {
    visit_residual(i, edges, planars, edge_matches, plane_matches,
                   [&]<class Fit>(const Fit& fit, const Eigen::Vector3d& p, ClassIndex c) {
                     typename Fit::Jacobian J;
                     const double distance = Fit::distance(fit.residual(T, p, &J));
                     sum.loss += settings.class_weight[c] * distance;
                     if (distance < settings.inlier_distance) {
                       ++sum.inliers;
                       sum.inlier_residual_sum += distance;
                     }
                     sum.hessian.noalias() += weight(c, distance) * J.transpose() * J;
                     const double clipped = std::min(distance, clip);
                     sum.class_squared_residuals[c] += clipped * clipped;
                     sum.class_dof[c] += Fit::kDof;
                   });
  };
  const FitSums sums =
      sum_in_blocks(edges.size() + planars.size(), settings.parallel, kResidualBlock, FitSums{}, term);
  result.loss = sums.loss;
  result.inliers = sums.inliers;
  result.inlier_residual_sum = sums.inlier_residual_sum;
  result.hessian = sums.hessian;
  result.class_squared_residuals = sums.class_squared_residuals;
  result.class_dof = sums.class_dof;
}

// Matches every feature at pose T to a line or plane fitted to its nearest
// map neighbours of its class (the expensive part: neighbour queries and fits).
void associate(const FeatureCloud& edges, const FeatureCloud& planars, const SemanticLocalMap& map, const Pose& T,
               const RegistrationSettings& settings, std::vector<Match>& edge_matches,
               std::vector<Match>& plane_matches, RegistrationResult& result) {
  const int ne = std::min(settings.edge_neighbours, kMaxNeighbours);
  const int np = std::min(settings.planar_neighbours, kMaxNeighbours);
  for_each_index(edges.size(), settings.parallel, 128, [&](std::size_t i) {
    std::array<Eigen::Vector3d, kMaxNeighbours> nb;
    Match m;
    const Eigen::Vector3d q = T * edges.points[i];
    if (gather(map.edges(), q, edges.classes[i], ne, settings.max_correspondence_distance, nb)) {
      if (auto line = fit_line(std::span<const Eigen::Vector3d>(nb.data(), ne))) {
        // d x up is horizontal and across d; it vanishes only for an upright line.
        if (std::abs(line->direction.dot(settings.up)) < settings.level_line_max_rise) {
          m.fit = PointToPlane{Plane{line->point, line->direction.cross(settings.up).normalized()}};
        } else {
          m.fit = PointToLine{*line};
        }
      }
    }
    edge_matches[i] = m;
  });
  for_each_index(planars.size(), settings.parallel, 128, [&](std::size_t i) {
    std::array<Eigen::Vector3d, kMaxNeighbours> nb;
    Match m;
    const Eigen::Vector3d q = T * planars.points[i];
    const ClassIndex c = planars.classes[i];
    if (gather(map.planars(), q, c, np, settings.max_correspondence_distance, nb)) {
      if (auto plane = fit_plane(std::span<const Eigen::Vector3d>(nb.data(), np))) {
        if (plane_satisfies_constraint(plane->normal, settings.orientation[c], settings.plane_normal_tolerance,
                                       settings.up)) {
          m.fit = PointToPlane{*plane};
        } else {
          m.rejected_by_constraint = true;
        }
      }
    }
    plane_matches[i] = m;
  });
  ++result.associations;
  result.edge_matches = 0;
  result.planar_matches = 0;
  result.rejected_by_constraint = 0;
  for (const auto& m : edge_matches) result.edge_matches += m.matched();
  for (const auto& m : plane_matches) {
    result.planar_matches += m.matched();
    result.rejected_by_constraint += m.rejected_by_constraint;
  }
}

// Gauss-Newton's normal equations H delta = -g: H = sum of w J^T J and
// g = sum of w J^T r over the matched features, w = class weight * Huber.
struct NormalEquations {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Vector6d g = Vector6d::Zero();

  NormalEquations& operator+=(const NormalEquations& o) {
    H += o.H;
    g += o.g;
    return *this;
  }
};

// The normal equations at pose T over the given correspondences.
NormalEquations normal_equations(const FeatureCloud& edges, const FeatureCloud& planars,
                                 const std::vector<Match>& edge_matches, const std::vector<Match>& plane_matches,
                                 const Pose& T, const RegistrationSettings& settings) {
  const ClassWeightedHuber weight{settings.class_weight, settings.robust_kernel_scale};
  const auto term = [&](std::size_t i, NormalEquations& sum) {
    visit_residual(i, edges, planars, edge_matches, plane_matches,
                   [&]<class Fit>(const Fit& fit, const Eigen::Vector3d& p, ClassIndex c) {
                     typename Fit::Jacobian J;
                     const typename Fit::Residual r = fit.residual(T, p, &J);
                     Fit::add_normal_terms(weight(c, Fit::distance(r)), J, r, sum.H, sum.g);
                   });
  };
  return sum_in_blocks(edges.size() + planars.size(), settings.parallel, kResidualBlock, NormalEquations{}, term);
}

// The RMS distance of the features from the sensor [m] (at least 1 m): the
// lever arm at which normalized_hessian() weighs rotations.
double feature_lever(const FeatureCloud& edges, const FeatureCloud& planars) {
  double sum = 0;
  for (const auto& p : edges.points) sum += p.squaredNorm();
  for (const auto& p : planars.points) sum += p.squaredNorm();
  const auto n = static_cast<double>(edges.size() + planars.size());
  return n > 0 ? std::max(1.0, std::sqrt(sum / n)) : 1.0;
}

// The eigen-decomposition of normalized_hessian(): eigenvalues ascending.
Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> normalized_eigen(const Eigen::Matrix<double, 6, 6>& H,
                                                                             int correspondences, double lever) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(normalized_hessian(H, correspondences, lever));
}

// Solution remapping (Zhang et al. 2016): the step without its components
// along the degenerate directions of H, so that the pose keeps the initial
// guess there. The directions are orthonormal in the normalised coordinates
// y = (rho, lever * phi), where the step is projected.
Vector6d without_degenerate_directions(const Vector6d& delta, const Eigen::Matrix<double, 6, 6>& H,
                                       int correspondences, double lever, double threshold) {
  const auto eig = normalized_eigen(H, correspondences, lever);
  Vector6d scale;
  scale << 1, 1, 1, lever, lever, lever;
  Vector6d y = scale.asDiagonal() * delta;
  bool degenerate = false;
  for (int i = 0; i < 6 && eig.eigenvalues()(i) < threshold; ++i) {
    const Vector6d u = eig.eigenvectors().col(i);
    y -= u.dot(y) * u;
    degenerate = true;
  }
  if (!degenerate) return delta;
  return scale.cwiseInverse().asDiagonal() * y;
}

// Gauss-Newton over the given correspondences from T; false when a step is
// not finite (T is then the last finite pose).
bool solve(const FeatureCloud& edges, const FeatureCloud& planars, const std::vector<Match>& edge_matches,
           const std::vector<Match>& plane_matches, const RegistrationSettings& settings, double lever, Pose& T,
           RegistrationResult& result) {
  for (int it = 0; it < settings.max_iterations; ++it) {
    auto [H, g] = normal_equations(edges, planars, edge_matches, plane_matches, T, settings);
    const Eigen::Matrix<double, 6, 6> undamped = H;
    // Small Levenberg-Marquardt damping keeps weakly constrained directions stable.
    H.diagonal().array() += 1e-6 * H.diagonal().maxCoeff() + 1e-9;
    Vector6d delta = -H.ldlt().solve(g);
    if (settings.degeneracy_eigenvalue > 0) {
      delta = without_degenerate_directions(delta, undamped, result.correspondences(), lever,
                                            settings.degeneracy_eigenvalue);
    }
    if (!delta.allFinite()) return false;
    T = apply_update(delta, T);
    ++result.iterations;
    result.converged = delta.head<3>().norm() < 1e-5 && delta.tail<3>().norm() < 1e-6;
    if (result.converged) break;
  }
  return true;
}

// Whether to associate again after `rounds` rounds, the last of which moved
// the pose by `moved`, all of them by `from_initial`. `refresh` moves the
// scan's points (e.g. de-skews them again) for the next round and says
// whether it did; it runs only when another round follows. Up to
// outer_iterations rounds, a refreshed scan or a pose that moved by the
// re-association thresholds goes on; beyond, up to far_outer_iterations, a
// scan that started far off (kFarTranslation, kFarRotation) while its pose
// still moves so (a refresh alone, which follows every pose change of a fast
// turn, does not).
template <typename Refresh>
bool another_round(int rounds, const Pose& moved, const Pose& from_initial, const RegistrationSettings& s,
                   const Refresh& refresh) {
  const bool moving = moved.translation().norm() >= s.reassociation_min_translation ||
                      rotation_angle(moved) >= s.reassociation_min_rotation;
  if (rounds < s.outer_iterations) return refresh() || moving;
  const bool far = from_initial.translation().norm() >= kFarTranslation || rotation_angle(from_initial) >= kFarRotation;
  const bool thresholds = s.reassociation_min_translation > 0 && s.reassociation_min_rotation > 0;
  if (rounds >= s.far_outer_iterations || !thresholds || !far || !moving) return false;
  refresh();
  return true;
}

// Outer rounds: associate at the current pose, solve, refresh the scan (e.g.
// de-skew it again). Re-associating only pays when the pose or the points
// moved: a shift well below the map resolution leaves the neighbour sets
// (nearly) unchanged.
RegistrationResult register_features(const FeatureCloud& edges, const FeatureCloud& planars,
                                     const SemanticLocalMap& map, const Pose& initial,
                                     const RegistrationSettings& settings, const std::function<bool(const Pose&)>& refresh) {
  RegistrationResult result;
  result.pose = initial;
  Pose T = initial;
  std::vector<Match> edge_matches(edges.size());
  std::vector<Match> plane_matches(planars.size());
  const double lever = feature_lever(edges, planars);
  for (int rounds = 1;; ++rounds) {
    const Pose round_start = T;
    associate(edges, planars, map, T, settings, edge_matches, plane_matches, result);
    if (result.correspondences() < 20) return result;  // not enough to constrain 6 DoF reliably
    if (!solve(edges, planars, edge_matches, plane_matches, settings, lever, T, result)) return result;
    const Pose moved = round_start.inverse() * T, from_initial = initial.inverse() * T;
    if (!another_round(rounds, moved, from_initial, settings, [&] { return refresh && refresh(T); })) break;
  }
  result.pose = T;
  result.ok = true;
  evaluate_fit(edges, planars, edge_matches, plane_matches, T, settings, result);
  const auto eig = normalized_eigen(result.hessian, result.correspondences(), lever);
  result.smallest_eigenvalue = eig.eigenvalues()(0);
  for (int i = 0; i < 6 && eig.eigenvalues()(i) < settings.degeneracy_eigenvalue; ++i) ++result.degenerate_directions;
  return result;
}

}  // namespace

RegistrationResult register_scan(const FeatureCloud& edges, const FeatureCloud& planars,
                                 const SemanticLocalMap& map, const Pose& initial,
                                 const RegistrationSettings& settings) {
  return register_features(edges, planars, map, initial, settings, {});
}

RegistrationResult register_scan(ScanFeatures& scan, const SemanticLocalMap& map, const Pose& initial,
                                 const RegistrationSettings& settings, const FeatureRefresh& refresh) {
  std::function<bool(const Pose&)> hook;
  if (refresh) {
    hook = [&](const Pose& pose) {
      const std::size_t edges = scan.edges.size(), planars = scan.planars.size();
      const bool changed = refresh(pose, scan);
      if (scan.edges.size() != edges || scan.planars.size() != planars) {
        throw std::logic_error("register_scan: a feature refresh must keep the number of points");
      }
      return changed;
    };
  }
  return register_features(scan.edges, scan.planars, map, initial, settings, hook);
}

}  // namespace saloam
