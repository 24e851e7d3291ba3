#pragma once
// Trajectory accuracy metrics: the KITTI odometry benchmark's relative error,
// the absolute trajectory error (ATE) after Umeyama alignment, the relative
// pose error (RPE) between consecutive frames, the ATE per axis of the
// sensor's frame (sideways, vertical, forward), and the scale bias (forward,
// lateral, vertical) of the distance travelled.
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
/// Requires equal sizes. kSim3 on a trajectory that does not move (positions
/// within 1 um of their mean) throws std::invalid_argument: its scale is
/// undefined (Umeyama's would be 0, an ATE of 0).
AteMetrics compute_ate(const std::vector<Pose>& gt, const std::vector<Pose>& est,
                       Alignment alignment = Alignment::kSE3);

/// Pairs two timestamped trajectories by time, as TUM's associate.py: each
/// time of `est` with the nearest of `gt` when they are at most
/// `max_difference` [s] apart, each `gt` time used once, in time order. Both
/// lists increase. Returns (gt index, est index) pairs; times without a
/// partner are left out.
std::vector<std::pair<std::size_t, std::size_t>> associate_by_time(const std::vector<double>& gt,
                                                                   const std::vector<double>& est,
                                                                   double max_difference);

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
// Scale bias
// ---------------------------------------------------------------------------

/// Systematic error of the distance travelled, along and across the motion.
///
/// The path is cut into consecutive windows of `delta` frames ([0, delta],
/// [delta, 2 delta], ...). In each, g and e are the translations of the
/// ground-truth and estimated relative motions inv(G_i) G_{i+delta} and
/// inv(E_i) E_{i+delta} (in the first pose's body frame) and d = e - g their
/// error, resolved in the window's motion frame: forward f = g / |g|, vertical
/// u = the body's up axis made orthogonal to f, lateral l = u x f (to the
/// left). Each bias is the sum of that component of d over all windows divided
/// by the sum of |g| (the path length, measured by chords), in percent: the
/// forward bias is -0.1 % when the estimate makes every stretch 0.1 % short.
/// Unlike the KITTI relative error, random errors average out and only a
/// systematic one stays. Windows with |g| < 1 mm (standing still) have no
/// direction and are left out.
///
/// The body's up axis is read from the ground truth's convention: -y when it
/// moves mostly along its body z axis (a KITTI camera frame: x right, y down,
/// z forward), +z when mostly along body x (a LiDAR frame: x forward, y left,
/// z up). With neither (or no motion) the lateral and vertical biases are NaN.
struct ScaleBias {
  std::size_t delta = 10;       ///< frames per window
  std::size_t windows = 0;      ///< windows summed
  double length_m = 0.0;        ///< sum of the windows' ground-truth lengths |g|
  double forward_percent = 0.0;   ///< NaN without windows
  double lateral_percent = 0.0;   ///< positive: the estimate drifts to the left; NaN without an up axis
  double vertical_percent = 0.0;  ///< positive: the estimate climbs; NaN without an up axis
  Eigen::Vector3d body_up = Eigen::Vector3d::Zero();  ///< the up axis used; zero when none was found
};

/// The up axis of the ground truth's body frame (see ScaleBias), or zero.
Eigen::Vector3d body_up_axis(const std::vector<Pose>& gt, std::size_t delta = 10);

/// ScaleBias of `est` against `gt`. Requires equal sizes and delta > 0.
ScaleBias compute_scale_bias(const std::vector<Pose>& gt, const std::vector<Pose>& est, std::size_t delta = 10);

// ---------------------------------------------------------------------------
// ATE per axis of the sensor's frame
// ---------------------------------------------------------------------------

/// The aligned position errors resolved in each ground-truth pose's own body
/// frame: per pose the error p_gt - T p_est (T the ATE's alignment) is
/// rotated into that pose's frame and split into sideways (left), vertical
/// (the body's up axis) and forward components; each field is the RMS of
/// one component over all poses, so the three squared add up to the ATE's
/// squared RMSE. Unlike the world axes, these follow the vehicle: on a
/// climbing route "vertical" is the sensor's up, the direction a pitch or
/// ground-height error moves it. The axes are read from the ground truth's
/// convention as in ScaleBias (camera frame: up -y, forward z; LiDAR frame:
/// up z, forward x); with neither all three are NaN.
struct AteAxes {
  double sideways_m = 0.0;
  double vertical_m = 0.0;
  double forward_m = 0.0;
};

/// AteAxes of `est` against `gt` with the alignment `ate` found (its
/// transform), the body's up axis `body_up` (body_up_axis()). Requires equal sizes.
AteAxes compute_ate_axes(const std::vector<Pose>& gt, const std::vector<Pose>& est, const AteMetrics& ate,
                         const Eigen::Vector3d& body_up);

// ---------------------------------------------------------------------------
// Everything at once
// ---------------------------------------------------------------------------

struct EvaluationOptions {
  Alignment alignment = Alignment::kSE3;
  KittiOptions kitti;
  std::size_t rpe_delta = 1;
  std::size_t bias_delta = 10;  ///< frames per window of the scale bias
};

struct TrajectoryEvaluation {
  std::size_t gt_poses = 0;         ///< poses in the ground truth given
  std::size_t est_poses = 0;        ///< poses in the estimate given
  std::size_t evaluated_poses = 0;  ///< common prefix that was evaluated
  double gt_length_m = 0.0;         ///< path length of the evaluated ground truth
  KittiMetrics kitti;
  AteMetrics ate;
  AteAxes ate_axes;  ///< the aligned ATE per axis of the sensor's frame
  RpeMetrics rpe;
  ScaleBias bias;
  /// Non-fatal problems (e.g. different lengths); the caller decides how to show them.
  std::vector<std::string> warnings;
};

/// Evaluates `est` against `gt`. With different sizes only the common prefix
/// is evaluated (an interrupted run writes fewer poses) and a warning is
/// recorded; an empty prefix throws std::invalid_argument.
TrajectoryEvaluation evaluate_trajectories(const std::vector<Pose>& gt, const std::vector<Pose>& est,
                                           const EvaluationOptions& options = {});

}  // namespace saloam
