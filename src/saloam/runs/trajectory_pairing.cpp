#include "saloam/runs/trajectory_pairing.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/eval/trajectory_metrics.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/runs/output_folder.hpp"

namespace saloam {
namespace {

/// TUM files are LiDAR-frame poses (as saloam writes poses_tum.txt), KITTI
/// files camera-frame poses (poses.txt): comparing one with the other needs
/// Tr, which converts the TUM side to the camera frame (P = Tr Q Tr^-1).
void make_frames_consistent(const std::string& gt_file, const std::string& est_file,
                            const std::optional<std::filesystem::path>& calib_file, Trajectory& gt,
                            TrajectoryFormat gt_format, Trajectory& est, TrajectoryFormat est_format) {
  if (gt_format == est_format) {
    if (calib_file) {
      spdlog::warn("--calib unused: both files are {}", gt_format == TrajectoryFormat::kTum ? "TUM" : "KITTI");
    }
    return;
  }
  const bool est_is_tum = est_format == TrajectoryFormat::kTum;
  const std::string& tum_file = est_is_tum ? est_file : gt_file;
  const std::string& kitti_file = est_is_tum ? gt_file : est_file;
  if (!calib_file) {
    throw InputError(tum_file, fmt::format("TUM trajectory (LiDAR frame, as poses_tum.txt) compared with the KITTI "
                                           "trajectory {} (camera frame, as poses.txt): pass --calib SEQ/calib.txt "
                                           "to convert it to the camera frame, or compare two files of one format",
                                           kitti_file));
  }
  Trajectory& tum = est_is_tum ? est : gt;
  tum.poses = lidar_to_camera_poses(tum.poses, read_velo_to_cam(*calib_file));
}

/// A simulated sequence whose trajectory's heights do not fit one ground has
/// poses_sensor.txt beside poses.txt: where the scans were really taken. An
/// odometry drifts from those, so scoring it against poses.txt adds the
/// trajectory's own height errors to its error.
void warn_if_scans_were_taken_elsewhere(const std::filesystem::path& gt_file) {
  if (gt_file.filename() != "poses.txt") return;
  const auto sensor = gt_file.parent_path() / "poses_sensor.txt";
  if (!std::filesystem::is_regular_file(sensor)) return;
  spdlog::warn("{} has {} beside it: the simulator took this sequence's scans there (it rode the sensor on the ground "
               "where the trajectory's heights do not fit one); score an odometry against --gt {}",
               gt_file.string(), sensor.filename().string(), sensor.string());
}

/// `trajectory` from its `skip`-th pose on, re-based on that pose (world =
/// the first pose kept, as a run's results are).
void drop_first(Trajectory& trajectory, std::size_t skip, const std::string& file, std::size_t first_frame) {
  if (skip >= trajectory.size()) {
    throw InputError(file, fmt::format("{} poses, none of them at frame {} where the other trajectory starts",
                                       trajectory.size(), first_frame));
  }
  const auto begin = static_cast<std::ptrdiff_t>(skip);
  trajectory.poses.erase(trajectory.poses.begin(), trajectory.poses.begin() + begin);
  trajectory.timestamps.erase(trajectory.timestamps.begin(), trajectory.timestamps.begin() + begin);
  const Pose rebase = trajectory.poses.front().inverse();
  for (Pose& pose : trajectory.poses) pose = orthonormalized(rebase * pose);
}

/// Pairs the poses by frame: a run's result starts at the first frame its
/// summary.json records (`odom SEQ --frames 5:` writes frames 5, 6, ...),
/// a sequence's poses.txt at frame 0.
void pair_by_frame(const std::string& gt_file, const std::string& est_file, Trajectory& gt, Trajectory& est) {
  const std::size_t gt_first = recorded_first_frame(gt_file).value_or(0);
  const std::size_t est_first = recorded_first_frame(est_file).value_or(0);
  if (gt_first == est_first) return;
  if (est_first > gt_first) {
    drop_first(gt, est_first - gt_first, gt_file, est_first);
  } else {
    drop_first(est, gt_first - est_first, est_file, gt_first);
  }
  spdlog::info("pairing by frame: the estimate starts at frame {}, the ground truth at frame {} (from the runs' "
               "summary.json)",
               est_first, gt_first);
}

/// Two TUM files carry their times: their poses are paired by time (the
/// nearest within 0.02 s, or half the ground truth's median interval when
/// that is less), never by line; poses without a partner are left out.
void pair_by_time(const std::string& est_file, Trajectory& gt, Trajectory& est) {
  double tolerance = 0.02;  // [s] TUM's associate.py
  if (gt.timestamps.size() > 1) {
    std::vector<double> gaps;
    for (std::size_t i = 1; i < gt.timestamps.size(); ++i) gaps.push_back(gt.timestamps[i] - gt.timestamps[i - 1]);
    std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2), gaps.end());
    tolerance = std::min(tolerance, 0.5 * gaps[gaps.size() / 2]);
  }
  const auto pairs = associate_by_time(gt.timestamps, est.timestamps, tolerance);
  if (pairs.size() < 2) {
    throw InputError(est_file,
                     fmt::format("{} of its {} times ({:.9f}..{:.9f}) lie within {:.3g} s of one of the ground "
                                 "truth's {} ({:.9f}..{:.9f}): TUM files are paired by time (do their clocks differ?)",
                                 pairs.size(), est.size(), est.timestamps.front(), est.timestamps.back(), tolerance,
                                 gt.size(), gt.timestamps.front(), gt.timestamps.back()));
  }
  Trajectory paired_gt, paired_est;
  for (const auto& [g, e] : pairs) {
    paired_gt.timestamps.push_back(gt.timestamps[g]);
    paired_gt.poses.push_back(gt.poses[g]);
    paired_est.timestamps.push_back(est.timestamps[e]);
    paired_est.poses.push_back(est.poses[e]);
  }
  if (pairs.size() != gt.size() || pairs.size() != est.size()) {
    spdlog::warn("paired {} poses by time (within {:.3g} s): {} of the ground truth's {} and {} of the estimate's {} "
                 "have no partner and are left out",
                 pairs.size(), tolerance, gt.size() - pairs.size(), gt.size(), est.size() - pairs.size(), est.size());
  }
  gt = std::move(paired_gt);
  est = std::move(paired_est);
}

}  // namespace

TrajectoryPair read_trajectory_pair(const std::filesystem::path& gt_path, const std::filesystem::path& est_path,
                                    const std::optional<std::filesystem::path>& calib_file) {
  const std::string gt_file = gt_path.string(), est_file = est_path.string();
  warn_if_scans_were_taken_elsewhere(gt_file);
  TrajectoryFormat gt_format{}, est_format{};
  TrajectoryPair pair;
  pair.gt = read_trajectory(gt_path, &gt_format);
  pair.est = read_trajectory(est_path, &est_format);
  make_frames_consistent(gt_file, est_file, calib_file, pair.gt, gt_format, pair.est, est_format);
  if (gt_format == TrajectoryFormat::kTum && est_format == TrajectoryFormat::kTum) {
    pair_by_time(est_file, pair.gt, pair.est);
  } else {
    pair_by_frame(gt_file, est_file, pair.gt, pair.est);
  }
  return pair;
}

}  // namespace saloam
