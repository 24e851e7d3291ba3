#include "saloam/slam/loop_verification.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "saloam/core/lie.hpp"

namespace saloam {

namespace {
// The coarse stage: correspondences up to 2 m and a Huber scale of 0.5 m
// pull a scan in from a few metres and degrees off; five re-associations let
// the neighbour sets follow it. Every third feature is enough to find the
// basin of the fine fit, at a third of the cost.
constexpr double kCoarseDistance = 2.0;     // [m]
constexpr double kCoarseKernel = 0.5;       // [m]
constexpr int kCoarseRounds = 5;
constexpr std::size_t kCoarseStride = 3;
// Uniqueness test: fine fits started this far [m] along the least
// constrained direction; a fit farther than 0.5 m or 2 deg from the best is
// a different solution.
constexpr double kAmbiguityShifts[] = {-3.0, -1.5, 1.5, 3.0};
constexpr double kDistinctTranslation = 0.5;
constexpr double kDistinctRotation = 2.0 * M_PI / 180;
constexpr int kFineRounds = 4;
constexpr int kIterations = 15;

FeatureCloud every_nth(const FeatureCloud& cloud, std::size_t n) {
  FeatureCloud out;
  for (std::size_t i = 0; i < cloud.size(); i += n) out.push_back(cloud.points[i], cloud.classes[i], cloud.sweep_time[i]);
  return out;
}

FeatureCloud transformed(const FeatureCloud& cloud, const Pose& T) {
  FeatureCloud out = cloud;
  for (auto& p : out.points) p = T * p;
  return out;
}
}  // namespace

LoopVerificationSettings LoopVerificationSettings::from_config(const SaloamConfig& config) {
  LoopVerificationSettings s;
  s.fine = RegistrationSettings::from_config(config.odometry);
  s.fine.parallel = false;
  s.fine.max_iterations = kIterations;
  s.fine.outer_iterations = kFineRounds;
  s.fine.inlier_distance = config.loop.inlier_distance;
  s.coarse = s.fine;
  s.coarse.max_correspondence_distance = kCoarseDistance;
  s.coarse.robust_kernel_scale = kCoarseKernel;
  s.coarse.outer_iterations = kCoarseRounds;
  s.voxel_size = class_voxel_sizes(config.odometry);
  s.loss_test = config.loop.acceptance == "loss";
  s.delta_r = config.loop.delta_r;
  s.max_mean_residual = config.loop.max_mean_residual;
  s.min_inlier_fraction = config.loop.min_inlier_fraction;
  s.min_translation_eigenvalue = config.loop.min_translation_eigenvalue;
  s.max_runner_up_ratio = config.loop.max_runner_up_ratio;
  return s;
}

LoopSubmap::LoopSubmap(const LoopVerificationSettings& settings)
    : coarse_(std::numeric_limits<int>::max(), settings.voxel_size, settings.coarse.max_correspondence_distance),
      fine_(std::numeric_limits<int>::max(), settings.voxel_size, settings.fine.max_correspondence_distance) {}

void LoopSubmap::add(const ScanFeatures& features, const Pose& candidate_from_keyframe) {
  const FeatureCloud edges = transformed(features.edges, candidate_from_keyframe);
  const FeatureCloud planars = transformed(features.planars, candidate_from_keyframe);
  coarse_.add_frame(edges, planars);
  fine_.add_frame(edges, planars);
}

LoopVerification verify_loop(const ScanFeatures& query, const LoopSubmap& submap, std::span<const Pose> guesses,
                             const LoopVerificationSettings& settings) {
  LoopVerification best;
  best.features = query.edges.size() + query.planars.size();
  best.reason = "no initial guess";
  const FeatureCloud coarse_edges = every_nth(query.edges, kCoarseStride);
  const FeatureCloud coarse_planars = every_nth(query.planars, kCoarseStride);
  std::vector<RegistrationResult> fits;
  for (const Pose& guess : guesses) {
    const RegistrationResult coarse =
        register_scan(coarse_edges, coarse_planars, submap.coarse(), guess, settings.coarse);
    fits.push_back(coarse.ok ? register_scan(query.edges, query.planars, submap.fine(), coarse.pose, settings.fine)
                             : coarse);
  }
  auto best_of = [&] {
    std::size_t index = fits.size();
    for (std::size_t g = 0; g < fits.size(); ++g) {
      if (fits[g].ok && (index == fits.size() || fits[g].inliers > fits[index].inliers)) index = g;
    }
    return index;
  };
  const std::size_t winner = best_of();
  if (winner == fits.size()) {
    best.reason = "registration failed (too few correspondences)";
    return best;
  }
  best.guess = winner;
  best.registration = fits[winner];
  // Uniqueness: start again a few metres along the least constrained
  // direction (along the road, where rows of trees, poles and parked cars
  // repeat); a different fit about as good as the best makes the place
  // ambiguous.
  const Eigen::Matrix3d block = best.registration.hessian.topLeftCorner<3, 3>();
  const Eigen::Vector3d weakest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(block).eigenvectors().col(0);
  for (const double shift : kAmbiguityShifts) {
    if (!std::isfinite(settings.max_runner_up_ratio)) break;  // test off: no extra fits
    Pose start = best.registration.pose;
    start.translation() += best.registration.pose.rotation() * (shift * weakest);
    const RegistrationResult other = register_scan(query.edges, query.planars, submap.fine(), start, settings.fine);
    if (!other.ok) continue;
    const Pose difference = best.registration.pose.inverse() * other.pose;
    const bool distinct = difference.translation().norm() > kDistinctTranslation ||
                          rotation_angle(difference) > kDistinctRotation;
    if (!distinct) continue;
    best.runner_up_inlier_ratio =
        std::max(best.runner_up_inlier_ratio, static_cast<double>(other.inliers) / std::max(1, best.registration.inliers));
  }
  for (std::size_t g = 0; g < fits.size(); ++g) {
    if (g == winner || !fits[g].ok) continue;
    const Pose difference = best.registration.pose.inverse() * fits[g].pose;
    if (difference.translation().norm() > kDistinctTranslation || rotation_angle(difference) > kDistinctRotation) {
      best.runner_up_inlier_ratio = std::max(
          best.runner_up_inlier_ratio, static_cast<double>(fits[g].inliers) / std::max(1, best.registration.inliers));
    }
  }
  const RegistrationResult& r = best.registration;
  best.relative = orthonormalized(r.pose);
  best.inlier_fraction = best.features > 0 ? static_cast<double>(r.inliers) / static_cast<double>(best.features) : 0.0;
  best.mean_residual = r.mean_inlier_residual();
  const Eigen::Matrix3d translation_block = r.hessian.topLeftCorner<3, 3>() / std::max(1, r.correspondences());
  best.translation_eigenvalue = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(translation_block).eigenvalues()(0);

  best.passes_loss_test = r.loss < settings.delta_r;
  best.passes_normalized_test = best.mean_residual <= settings.max_mean_residual &&
                                best.inlier_fraction >= settings.min_inlier_fraction &&
                                best.translation_eigenvalue >= settings.min_translation_eigenvalue &&
                                best.runner_up_inlier_ratio < settings.max_runner_up_ratio;
  best.accepted = settings.loss_test ? best.passes_loss_test : best.passes_normalized_test;
  if (best.accepted) {
    best.reason.clear();
  } else if (settings.loss_test) {
    best.reason = fmt::format("loss r = {:.1f} >= delta_r = {:.1f}", r.loss, settings.delta_r);
  } else if (best.inlier_fraction < settings.min_inlier_fraction) {
    best.reason = fmt::format("inlier fraction {:.2f} < {:.2f}", best.inlier_fraction, settings.min_inlier_fraction);
  } else if (best.runner_up_inlier_ratio >= settings.max_runner_up_ratio) {
    best.reason = fmt::format("ambiguous: another fit has {:.0f} % of the inliers", 100 * best.runner_up_inlier_ratio);
  } else if (best.mean_residual > settings.max_mean_residual) {
    best.reason = fmt::format("mean residual {:.3f} m > {:.3f} m", best.mean_residual, settings.max_mean_residual);
  } else {
    best.reason = fmt::format("degenerate: translation eigenvalue {:.3f} < {:.3f}", best.translation_eigenvalue,
                              settings.min_translation_eigenvalue);
  }
  return best;
}

}  // namespace saloam
