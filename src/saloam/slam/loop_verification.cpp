#include "saloam/slam/loop_verification.hpp"

#include <algorithm>
#include <limits>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "saloam/core/lie.hpp"

namespace saloam {

namespace {
// The coarse stage: correspondences up to 3 m and a Huber scale of 0.5 m
// pull a scan in from a few metres and degrees off; five re-associations let
// the neighbour sets follow it.
constexpr double kCoarseDistance = 3.0;     // [m]
constexpr double kCoarseKernel = 0.5;       // [m]
constexpr int kCoarseRounds = 5;
constexpr int kFineRounds = 4;
constexpr int kIterations = 15;

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
  bool have_best = false;
  for (std::size_t g = 0; g < guesses.size(); ++g) {
    const RegistrationResult coarse =
        register_scan(query.edges, query.planars, submap.coarse(), guesses[g], settings.coarse);
    if (!coarse.ok) continue;
    const RegistrationResult fine =
        register_scan(query.edges, query.planars, submap.fine(), coarse.pose, settings.fine);
    if (!fine.ok) continue;
    if (!have_best || fine.inliers > best.registration.inliers) {
      best.registration = fine;
      best.guess = g;
      have_best = true;
    }
  }
  if (!have_best) {
    best.reason = "registration failed (too few correspondences)";
    return best;
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
                                best.translation_eigenvalue >= settings.min_translation_eigenvalue;
  best.accepted = settings.loss_test ? best.passes_loss_test : best.passes_normalized_test;
  if (best.accepted) {
    best.reason.clear();
  } else if (settings.loss_test) {
    best.reason = fmt::format("loss r = {:.1f} >= delta_r = {:.1f}", r.loss, settings.delta_r);
  } else if (best.inlier_fraction < settings.min_inlier_fraction) {
    best.reason = fmt::format("inlier fraction {:.2f} < {:.2f}", best.inlier_fraction, settings.min_inlier_fraction);
  } else if (best.mean_residual > settings.max_mean_residual) {
    best.reason = fmt::format("mean residual {:.3f} m > {:.3f} m", best.mean_residual, settings.max_mean_residual);
  } else {
    best.reason = fmt::format("degenerate: translation eigenvalue {:.3f} < {:.3f}", best.translation_eigenvalue,
                              settings.min_translation_eigenvalue);
  }
  return best;
}

}  // namespace saloam
