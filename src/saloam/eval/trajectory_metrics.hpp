#pragma once
// Trajectory accuracy metrics: the KITTI odometry benchmark's relative error,
// the absolute trajectory error (ATE) after Umeyama alignment, and the
// relative pose error (RPE) between consecutive frames.
//
// Pure computation, no I/O: reading files, printing and plotting live in
// evaluation_report.hpp and in the CLI. Trajectories are matched by index
// (pose i of the estimate belongs to pose i of the ground truth); both must be
// expressed in the same frame convention (e.g. KITTI camera-0 poses).
//
// Matrix inverses are general 4x4 inverses, not R^T: pose files store
// rotations that are orthonormal only to ~1e-6, and the KITTI devkit's numbers
// depend on that choice (see ../shared/data/kitti/README.md).

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/types.hpp"

namespace saloam {

// ---------------------------------------------------------------------------
// KITTI odometry benchmark (devkit evaluate_odometry.cpp)
// ---------------------------------------------------------------------------

/// Options of the KITTI relative error. The defaults are the benchmark's.
struct KittiOptions {
  /// Segment lengths along the ground truth [m].
  std::vector<double> lengths_m{100, 200, 300, 400, 500, 600, 700, 800};
  /// A segment starts at every `step_frames`-th frame.
  std::size_t step_frames = 10;
};

/// Errors of all segments of one length.
struct KittiLengthError {
  double length_m = 0.0;
  double t_err_percent = 0.0;        ///< mean translation error [%]; NaN without segments
  double r_err_deg_per_100m = 0.0;   ///< mean rotation error [deg/100 m]; NaN without segments
  std::size_t segments = 0;
};

/// One evaluated segment, [first_frame, last_frame].
struct KittiSegmentError {
  std::size_t first_frame = 0;
  std::size_t last_frame = 0;
  double length_m = 0.0;
  double t_err = 0.0;  ///< translation error / length [m/m]
  double r_err = 0.0;  ///< rotation error / length [rad/m]
};

struct KittiMetrics {
  /// Mean over ALL segments of all lengths (the benchmark's sequence value), in %.
  double t_err_percent = 0.0;
  /// Same for rotation, in deg per 100 m. Both are NaN when no segment fits
  /// (ground truth shorter than the shortest length).
  double r_err_deg_per_100m = 0.0;
  std::size_t segments = 0;
  std::vector<KittiLengthError> per_length;  ///< one entry per option length, in order
  std::vector<KittiSegmentError> segment_errors;
};

/// KITTI odometry relative error, as the official devkit defines it:
/// distances along the ground truth; for every first frame (every
/// `step_frames`) and length, the last frame is the first one whose distance
/// exceeds dist[first] + length (strictly, as in the devkit); the error pose is
/// inv(inv(E_first) E_last) * inv(G_first) G_last, t_err = |translation| / length,
/// r_err = acos(clamp((trace(R) - 1) / 2)) / length. Requires equal sizes.
KittiMetrics compute_kitti_metrics(const std::vector<Pose>& gt, const std::vector<Pose>& est,
                                   const KittiOptions& options = {});

/// Cumulative distance travelled along a trajectory (first entry 0) [m].
std::vector<double> trajectory_distances(const std::vector<Pose>& poses);

// ---------------------------------------------------------------------------
// Alignment and absolute trajectory error
// ---------------------------------------------------------------------------

enum class Alignment {
  kNone,  ///< compare raw positions
  kSE3,   ///< rotation + translation (Umeyama without scale); the default
  kSim3,  ///< rotation + translation + scale (monocular estimates)
};

/// Parses "none", "se3" or "sim3" (case-insensitive); throws std::invalid_argument.
Alignment parse_alignment(const std::string& name);
std::string alignment_name(Alignment alignment);

/// A similarity transform x -> scale * R x + t.
struct SimilarityTransform {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;

  [[nodiscard]] Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return scale * rotation * x + translation; }
  /// Applies the transform to a pose (rotation composed, position mapped; the
  /// scale acts on the position only).
  [[nodiscard]] Pose apply(const Pose& pose) const;
};

/// Least-squares transform mapping `source` onto `target` (Umeyama 1991,
/// "Least-squares estimation of transformation parameters between two point
/// patterns", eqs. 40-42), minimising sum |target_i - (s R source_i + t)|^2.
/// With `with_scale == false` s = 1. Needs at least 3 points for a unique
/// rotation (fewer points give a valid but not unique answer); throws
/// std::invalid_argument on empty or different-sized input.
SimilarityTransform umeyama_alignment(const std::vector<Eigen::Vector3d>& source,
                                      const std::vector<Eigen::Vector3d>& target, bool with_scale);

/// Summary statistics of a list of non-negative errors.
struct ErrorStats {
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double max = 0.0;
  double min = 0.0;
  std::size_t count = 0;
};
ErrorStats error_stats(const std::vector<double>& errors);

struct AteMetrics {
  Alignment alignment = Alignment::kSE3;
  SimilarityTransform transform;        ///< applied to the estimate (identity for kNone)
  ErrorStats aligned;                   ///< after `alignment`
  ErrorStats unaligned;                 ///< raw positions
  std::vector<double> aligned_errors;   ///< per pose |p_gt - T p_est| [m]
  std::vector<double> unaligned_errors; ///< per pose |p_gt - p_est| [m]
};

/// Absolute trajectory error of the positions (evo's APE, translation part).
/// Requires equal sizes.
AteMetrics compute_ate(const std::vector<Pose>& gt, const std::vector<Pose>& est,
                       Alignment alignment = Alignment::kSE3);

// ---------------------------------------------------------------------------
// Relative pose error
// ---------------------------------------------------------------------------

struct RpeMetrics {
  std::size_t delta = 1;       ///< frame distance of the compared pairs
  double trans_rmse_m = 0.0;
  double rot_rmse_deg = 0.0;
  ErrorStats trans;            ///< [m]
  ErrorStats rot;              ///< [deg]
  /// Entry k compares the motion from frame k to k + delta.
  std::vector<double> trans_errors_m;
  std::vector<double> rot_errors_deg;
};

/// Relative pose error between frames i and i + delta (evo's RPE): error pose
/// inv(inv(G_i) G_j) * inv(E_i) E_j, its translation norm and rotation angle.
/// Independent of any rigid alignment. Requires equal sizes.
RpeMetrics compute_rpe(const std::vector<Pose>& gt, const std::vector<Pose>& est, std::size_t delta = 1);

// ---------------------------------------------------------------------------
// Everything at once
// ---------------------------------------------------------------------------

struct EvaluationOptions {
  Alignment alignment = Alignment::kSE3;
  KittiOptions kitti;
  std::size_t rpe_delta = 1;
};

struct TrajectoryEvaluation {
  std::size_t gt_poses = 0;         ///< poses in the ground truth given
  std::size_t est_poses = 0;        ///< poses in the estimate given
  std::size_t evaluated_poses = 0;  ///< common prefix that was evaluated
  double gt_length_m = 0.0;         ///< path length of the evaluated ground truth
  KittiMetrics kitti;
  AteMetrics ate;
  RpeMetrics rpe;
  /// Non-fatal problems (e.g. different lengths); the caller decides how to show them.
  std::vector<std::string> warnings;
};

/// Evaluates `est` against `gt`. With different sizes only the common prefix
/// is evaluated (an interrupted run writes fewer poses) and a warning is
/// recorded; an empty prefix throws std::invalid_argument.
TrajectoryEvaluation evaluate_trajectories(const std::vector<Pose>& gt, const std::vector<Pose>& est,
                                           const EvaluationOptions& options = {});

}  // namespace saloam
