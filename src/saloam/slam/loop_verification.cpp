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
// constrained direction; a fit that is not same_fit() as the best is a
// different solution.
constexpr double kAmbiguityShifts[] = {-3.0, -1.5, 1.5, 3.0};
constexpr double kSameFitTranslation = 0.5;            // [m]
constexpr double kSameFitRotation = 2.0 * M_PI / 180;  // [rad]
// The fine stage re-associates until a round moves the pose less than the
// odometry's reassociation_min_translation / _rotation_deg, at most this
// often: a fit from a descriptor's yaw (no translation known) slides along
// a street for several rounds before its neighbour sets settle, and a fit
// judged before that is judged where it happened to stop (docs/loop_closure.md,
// "Fine-stage rounds").
constexpr int kFineRounds = 10;
constexpr int kIterations = 15;

FeatureCloud every_nth(const FeatureCloud& cloud, std::size_t n) {
  FeatureCloud out;
  for (std::size_t i = 0; i < cloud.size(); i += n) out.push_back(cloud.points[i], cloud.classes[i], cloud.sweep_time[i]);
  return out;
}

}  // namespace

LoopVerificationSettings LoopVerificationSettings::from_config(const SaloamConfig& config) {
  LoopVerificationSettings s;
  s.fine = RegistrationSettings::from_config(config.odometry);
  s.fine.parallel = false;
  s.fine.max_iterations = kIterations;
  s.fine.outer_iterations = kFineRounds;
  s.fine.far_outer_iterations = 0;  // a bounded budget per candidate, met or not
  s.fine.inlier_distance = config.loop.inlier_distance;
  // A loop's fit is judged for degeneracy (min_translation_eigenvalue), not held at its guess.
  s.fine.degeneracy_eigenvalue = 0;
  // Level lines are the odometry's rule: a loop's fit is judged by inlier
  // and residual thresholds measured with every edge matched to its line.
  s.fine.level_line_max_rise = 0;
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

namespace {

// The query at both stages: every third feature for the coarse fit, all for the fine one.
struct QueryFeatures {
  const ScanFeatures& all;
  FeatureCloud coarse_edges, coarse_planars;
};

RegistrationResult fit_from(const Pose& guess, const QueryFeatures& query, const LoopSubmap& submap,
                            const LoopVerificationSettings& settings) {
  const RegistrationResult coarse =
      register_scan(query.coarse_edges, query.coarse_planars, submap.coarse(), guess, settings.coarse);
  if (!coarse.ok) return coarse;
  return register_scan(query.all.edges, query.all.planars, submap.fine(), coarse.pose, settings.fine);
}

// Uniqueness: fits started a few metres along the least constrained
// direction (along the road, where rows of trees, poles and parked cars
// repeat); returns the inliers of the best distinct one over the fit's.
double runner_up_ratio(const RegistrationResult& fit, const QueryFeatures& query, const LoopSubmap& submap,
                       const LoopVerificationSettings& settings) {
  const Eigen::Matrix3d block = fit.hessian.topLeftCorner<3, 3>();
  const Eigen::Vector3d weakest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(block).eigenvectors().col(0);
  double ratio = 0;
  for (const double shift : kAmbiguityShifts) {
    Pose start = fit.pose;
    start.translation() += fit.pose.rotation() * (shift * weakest);
    const RegistrationResult other =
        register_scan(query.all.edges, query.all.planars, submap.fine(), start, settings.fine);
    if (!other.ok) continue;
    if (!same_fit(fit.pose, other.pose))
      ratio = std::max(ratio, static_cast<double>(other.inliers) / std::max(1, fit.inliers));
  }
  return ratio;
}

// Fills the fit statistics, both tests and the decision.
void judge(LoopVerification& v, const LoopVerificationSettings& settings) {
  const RegistrationResult& r = v.registration;
  v.relative = orthonormalized(r.pose);
  v.inlier_fraction = v.features > 0 ? static_cast<double>(r.inliers) / static_cast<double>(v.features) : 0.0;
  v.mean_residual = r.mean_inlier_residual();
  const Eigen::Matrix3d translation_block = r.hessian.topLeftCorner<3, 3>() / std::max(1, r.correspondences());
  v.translation_eigenvalue = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(translation_block).eigenvalues()(0);
  v.passes_loss_test = r.loss < settings.delta_r;
  v.passes_normalized_test = v.mean_residual <= settings.max_mean_residual &&
                             v.inlier_fraction >= settings.min_inlier_fraction &&
                             v.translation_eigenvalue >= settings.min_translation_eigenvalue &&
                             v.runner_up_inlier_ratio < settings.max_runner_up_ratio;
  v.accepted = settings.loss_test ? v.passes_loss_test : v.passes_normalized_test;
  if (v.accepted) {
    v.reason.clear();
  } else if (settings.loss_test) {
    v.reason = fmt::format("loss r = {:.1f} >= delta_r = {:.1f}", r.loss, settings.delta_r);
  } else if (v.inlier_fraction < settings.min_inlier_fraction) {
    v.reason = fmt::format("inlier fraction {:.2f} < {:.2f}", v.inlier_fraction, settings.min_inlier_fraction);
  } else if (v.runner_up_inlier_ratio >= settings.max_runner_up_ratio) {
    v.reason = fmt::format("ambiguous: another fit has {:.0f} % of the inliers", 100 * v.runner_up_inlier_ratio);
  } else if (v.mean_residual > settings.max_mean_residual) {
    v.reason = fmt::format("mean residual {:.3f} m > {:.3f} m", v.mean_residual, settings.max_mean_residual);
  } else {
    v.reason = fmt::format("degenerate: translation eigenvalue {:.3f} < {:.3f}", v.translation_eigenvalue,
                           settings.min_translation_eigenvalue);
  }
}

}  // namespace

LoopVerification verify_loop(const ScanFeatures& query, const LoopSubmap& submap, std::span<const Pose> guesses,
                             const LoopVerificationSettings& settings) {
  const QueryFeatures features{query, every_nth(query.edges, kCoarseStride), every_nth(query.planars, kCoarseStride)};
  LoopVerification best;
  best.features = query.edges.size() + query.planars.size();
  best.reason = guesses.empty() ? "no initial guess" : "registration failed (too few correspondences)";
  bool found = false;
  // Guesses in order; the first one whose fit is accepted ends the search
  // (the current estimate comes first and usually is that one).
  for (std::size_t g = 0; g < guesses.size() && !best.accepted; ++g) {
    LoopVerification candidate;
    candidate.features = best.features;
    candidate.guess = g;
    candidate.registration = fit_from(guesses[g], features, submap, settings);
    if (!candidate.registration.ok) continue;
    judge(candidate, settings);
    // Uniqueness only decides a fit that passes the rest of the normalized
    // test: its extra registrations are spent on those alone.
    if (std::isfinite(settings.max_runner_up_ratio) && candidate.passes_normalized_test) {
      candidate.runner_up_inlier_ratio = runner_up_ratio(candidate.registration, features, submap, settings);
      judge(candidate, settings);
    }
    if (!found || candidate.accepted || candidate.registration.inliers > best.registration.inliers) {
      best = std::move(candidate);
      found = true;
    }
  }
  return best;
}

namespace {
// Guesses closer than this to each other converge to the same fit: one is enough.
constexpr double kSameGuessTranslation = 1.0;            // [m]
constexpr double kSameGuessRotation = 5.0 * M_PI / 180;  // [rad]
// Added to H / N so that a direction no correspondence constrains still has
// a little information (the edge stays positive definite).
constexpr double kInformationFloor = 1e-3;
}  // namespace

bool same_fit(const Pose& a, const Pose& b) {
  const Pose difference = a.inverse() * b;
  return difference.translation().norm() <= kSameFitTranslation && rotation_angle(difference) <= kSameFitRotation;
}

Pose place_match_guess(const PlaceMatch& match) {
  Pose guess = Pose::Identity();
  if (match.yaw) {
    guess.linear() = Eigen::AngleAxisd(*match.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    if (match.translation) guess.translation().head<2>() = *match.translation;
  }
  return guess;
}

void add_distinct_guess(std::vector<Pose>& guesses, const Pose& guess) {
  const bool same = std::any_of(guesses.begin(), guesses.end(), [&](const Pose& g) {
    const Pose difference = g.inverse() * guess;
    return difference.translation().norm() <= kSameGuessTranslation && rotation_angle(difference) <= kSameGuessRotation;
  });
  if (!same) guesses.push_back(guess);
}

Matrix6d registration_information(const RegistrationResult& registration, double frames, double scale) {
  Matrix6d per_correspondence;
  if (registration.ok && registration.correspondences() > 0) {
    per_correspondence = registration.hessian / registration.correspondences();
  } else {
    // No registration (first frames, or a failure that kept the prediction):
    // what a typical scan gives, per correspondence.
    per_correspondence = Matrix6d::Zero();
    per_correspondence.diagonal() << 0.3, 0.3, 0.3, 30.0, 30.0, 30.0;
  }
  const double floor = kInformationFloor * std::max(1e-9, per_correspondence.trace() / 6.0);
  per_correspondence.diagonal().array() += floor;
  return scale / std::max(1.0, frames) * per_correspondence;
}

}  // namespace saloam
