#include "saloam/runs/loop_truth.hpp"

#include <cmath>

#include "saloam/core/lie.hpp"

namespace saloam {

namespace {
double heading_deg(const Pose& relative) {
  const Eigen::Vector3d x = relative.rotation().col(0);
  return std::abs(std::atan2(x.y(), x.x())) * 180.0 / M_PI;
}
}  // namespace

LoopTruthOptions LoopTruthOptions::from_config(const LoopClosureConfig& config) {
  LoopTruthOptions options;
  options.exclude_recent_distance = config.exclude_recent_distance;
  return options;
}

namespace {
/// The rule on the error truth^-1 * estimate.
bool within_truth_bounds(const Pose& error, const LoopTruthOptions& options) {
  return error.translation().norm() <= options.max_translation_error &&
         rotation_angle(error) * 180.0 / M_PI <= options.max_rotation_error_deg;
}
}  // namespace

bool agrees_with_truth(const Pose& estimate, const Pose& truth, const LoopTruthOptions& options) {
  return within_truth_bounds(truth.inverse() * estimate, options);
}

LoopTruth loop_truth(const LoopRecord& loop, const std::vector<Pose>& gt, const LoopTruthOptions& options) {
  LoopTruth truth;
  const Pose& gt_match = gt.at(loop.match_frame);
  const Pose& gt_query = gt.at(loop.query_frame);
  const Pose gt_relative = gt_match.inverse() * gt_query;
  const Pose error = gt_relative.inverse() * loop.verification.relative;
  truth.translation_error = error.translation().norm();
  truth.horizontal_error = (loop.verification.relative.translation() - gt_relative.translation()).head<2>().norm();
  truth.rotation_error_deg = rotation_angle(error) * 180.0 / M_PI;
  truth.gt_distance = gt_relative.translation().norm();
  truth.gt_yaw_deg = heading_deg(gt_relative);
  truth.correct = within_truth_bounds(error, options);
  return truth;
}

LoopSummary summarize_loops(const SlamSystem& slam, const std::vector<Pose>& gt, const LoopTruthOptions& options) {
  LoopSummary s;
  const auto& keyframes = slam.keyframes();
  std::vector<char> closed(keyframes.size(), 0);
  for (const auto& loop : slam.loops()) {
    ++s.verified;
    const LoopTruth truth = loop_truth(loop, gt, options);
    if (!loop.verification.accepted) {
      s.rejected_true += truth.correct;
      continue;
    }
    ++s.accepted;
    if (truth.correct) {
      ++s.accepted_true;
      s.accepted_reverse += truth.gt_yaw_deg > 90.0;
      closed[loop.query_keyframe] = 1;
    } else {
      ++s.accepted_false;
    }
  }
  // Revisit keyframes by the ground truth, grouped into stretches.
  bool in_stretch = false, stretch_closed = false, stretch_reverse = false;
  auto end_stretch = [&] {
    if (!in_stretch) return;
    ++s.revisit_stretches;
    s.missed_stretches += !stretch_closed;
    s.reverse_stretches += stretch_reverse;
    s.missed_reverse_stretches += stretch_reverse && !stretch_closed;
    in_stretch = false;
  };
  for (std::size_t q = 0; q < keyframes.size(); ++q) {
    const Pose& gq = gt.at(keyframes[q].frame);
    bool revisit = false, reverse = false;
    for (std::size_t j = 0; j < q; ++j) {
      if (keyframes[q].travelled - keyframes[j].travelled < options.exclude_recent_distance) break;
      const Pose& gj = gt.at(keyframes[j].frame);
      if ((gj.translation() - gq.translation()).norm() < options.revisit_distance) {
        revisit = true;
        reverse = reverse || heading_deg(gj.inverse() * gq) > 90.0;
      }
    }
    if (!revisit) {
      end_stretch();
      continue;
    }
    ++s.revisit_keyframes;
    if (!in_stretch) {
      in_stretch = true;
      stretch_closed = false;
      stretch_reverse = false;
    }
    stretch_closed = stretch_closed || closed[q];
    stretch_reverse = stretch_reverse || reverse;
  }
  end_stretch();
  return s;
}

}  // namespace saloam
