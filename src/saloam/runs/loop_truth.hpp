#pragma once
// Loop closures judged against ground truth: an accepted loop is true when
// its relative pose agrees with the ground truth's within 0.5 m and 2 deg;
// a stretch of keyframes that revisits an earlier place (by the ground
// truth) is missed when no true loop was accepted in it.

#include <cstddef>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/slam/slam_system.hpp"

namespace saloam {

struct LoopTruthOptions {
  double max_translation_error = 0.5;  ///< [m]
  double max_rotation_error_deg = 2.0;
  double revisit_distance = 3.0;       ///< [m] a keyframe this close (GT) to an earlier one revisits it
  /// [m] earlier = travelled at least this much before: the SLAM's
  /// loop.exclude_recent_distance (from_config), as its search.
  double exclude_recent_distance{};

  static LoopTruthOptions from_config(const LoopClosureConfig& config);
};

struct LoopTruth {
  double translation_error = 0;    ///< [m] |t| of (T_gt^-1 T_est) of the relative poses
  /// [m] the same without its vertical part (in the match's frame): where a
  /// trajectory's heights do not fit one ground surface the simulator rode
  /// the sensor on the ground, so poses.txt is wrong in height there only.
  double horizontal_error = 0;
  double rotation_error_deg = 0;
  double gt_distance = 0;          ///< [m] between the two keyframes' true positions
  double gt_yaw_deg = 0;           ///< true relative heading (about 180: a reverse revisit)
  bool correct = false;
};

/// Whether an estimate agrees with the truth within the options' 0.5 m and
/// 2 deg (the error is truth^-1 * estimate): the one rule that judges loops,
/// cross-session edges and relocalisations against ground truth.
bool agrees_with_truth(const Pose& estimate, const Pose& truth, const LoopTruthOptions& options = {});

/// Truth of one loop; `gt` holds the LiDAR-frame ground truth per processed frame.
LoopTruth loop_truth(const LoopRecord& loop, const std::vector<Pose>& gt, const LoopTruthOptions& options = {});

struct LoopSummary {
  std::size_t verified = 0;        ///< candidates that went through verification
  std::size_t accepted = 0;
  std::size_t accepted_true = 0;
  std::size_t accepted_false = 0;
  std::size_t accepted_reverse = 0;  ///< true loops with a relative heading beyond 90 deg
  std::size_t rejected_true = 0;     ///< rejected candidates whose verified pose was in fact right
  std::size_t revisit_keyframes = 0; ///< keyframes near an earlier one (GT)
  std::size_t revisit_stretches = 0; ///< runs of consecutive revisit keyframes
  std::size_t missed_stretches = 0;  ///< of those, without any true accepted loop
  std::size_t reverse_stretches = 0;         ///< stretches revisiting in the opposite direction
  std::size_t missed_reverse_stretches = 0;
};

LoopSummary summarize_loops(const SlamSystem& slam, const std::vector<Pose>& gt, const LoopTruthOptions& options);

}  // namespace saloam
