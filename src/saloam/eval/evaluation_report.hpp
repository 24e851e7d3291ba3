#pragma once
// Output of a trajectory evaluation: JSON for other tools, a Markdown table
// for people, and a top-down PNG plot. The metrics themselves are computed in
// trajectory_metrics.hpp; nothing here changes them.
//
// Typical use (demo, odometry accuracy runs):
//
//   const auto ev = evaluate_trajectories(gt, est);
//   for (const auto& w : ev.warnings) spdlog::warn("{}", w);
//   print_evaluation_markdown(std::cout, ev, {"00.txt", "odometry.txt"});
//   write_evaluation_json("eval.json", ev, {"00.txt", "odometry.txt"});
//   plot_evaluation("eval.png", gt, est, ev, {"00.txt", "odometry.txt"});

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "saloam/core/types.hpp"
#include "saloam/eval/trajectory_metrics.hpp"

namespace saloam {

/// Names shown in the outputs (usually the file names); may be empty.
struct EvaluationLabels {
  std::string gt_name;
  std::string est_name;
};

/// The evaluation as JSON. Keys (metres, percent, degrees as named):
///   gt, est, alignment, num_poses (evaluated), gt_poses, est_poses, gt_length_m,
///   kitti.{t_err_percent, r_err_deg_per_100m, segments,
///          per_length[{length_m, t_err_percent, r_err_deg_per_100m, segments}]},
///   ate.{alignment, rmse_aligned, mean_aligned, median_aligned, max_aligned,
///        rmse_unaligned, mean_unaligned, median_unaligned, max_unaligned,
///        scale, rotation (3x3 rows), translation, per_pose_aligned_m[],
///        per_axis_rmse.{sideways_m, vertical_m, forward_m} (AteAxes, after the alignment)},
///   rpe.{delta, trans_rmse_m, trans_mean_m, trans_median_m, trans_max_m,
///        rot_rmse_deg, rot_mean_deg, rot_median_deg, rot_max_deg,
///        per_frame_trans_m[], per_frame_rot_deg[]},
///   scale_bias.{delta, windows, length_m, forward_percent, lateral_percent,
///               vertical_percent, body_up (3)} (ScaleBias),
///   warnings[].
/// Undefined values (e.g. KITTI errors of a path shorter than 100 m) are null.
/// `per_frame == false` leaves out the per-pose/per-frame arrays.
nlohmann::json evaluation_to_json(const TrajectoryEvaluation& evaluation, const EvaluationLabels& labels = {},
                                  bool per_frame = true);

/// Writes evaluation_to_json (indented) to `file`; throws InputError when it cannot be written.
void write_evaluation_json(const std::filesystem::path& file, const TrajectoryEvaluation& evaluation,
                           const EvaluationLabels& labels = {});

/// A metric with `decimals` digits, or "n/a" when it is undefined (NaN, e.g.
/// the KITTI errors of a path shorter than 100 m).
std::string format_metric(double value, int decimals);

/// A Markdown summary: headline table and the KITTI per-length table.
void print_evaluation_markdown(std::ostream& out, const TrajectoryEvaluation& evaluation,
                               const EvaluationLabels& labels = {});

/// The two axes (0 = x, 1 = y, 2 = z), in increasing index order, along which
/// the ground truth extends most: x-z for KITTI camera poses (y points down),
/// x-y for LiDAR-frame poses. Plotting (first, second) as (horizontal,
/// vertical) gives an unmirrored top-down view in both conventions.
std::pair<int, int> top_down_axes(const std::vector<Pose>& gt);

/// Top-down PNG: ground truth in grey, the aligned estimate (evaluation.ate.transform
/// applied) coloured by its per-pose ATE with a colour bar; equal aspect, title
/// with the headline numbers. Uses the evaluated common prefix of gt and est.
void plot_evaluation(const std::filesystem::path& file, const std::vector<Pose>& gt, const std::vector<Pose>& est,
                     const TrajectoryEvaluation& evaluation, const EvaluationLabels& labels = {});

}  // namespace saloam
