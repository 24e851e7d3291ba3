#pragma once
// Writes a trajectory as it is computed, in the two formats every run emits:
//   KITTI (12 numbers a line): camera-frame convention of the ground truth,
//     P_i = Tr Q_i Tr^-1, so `saloam eval`, the KITTI devkit and evo compare it
//     with poses.txt directly; LiDAR-frame poses when no Tr is known
//   TUM (timestamp x y z qx qy qz qw): LiDAR-frame poses Q_i = T_L0<-Li
// Each line is flushed as soon as it is written: an interrupted run keeps
// every frame it finished. The files are created with the first pose: a run
// that stops before its first frame (e.g. an unreadable first scan) leaves no
// pose file that could be taken for a result.

#include <filesystem>
#include <fstream>
#include <optional>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

class TrajectoryWriter {
 public:
  /// Removes both files if they exist (an earlier run's); InputError when
  /// that fails. Nothing is created yet.
  TrajectoryWriter(std::filesystem::path kitti_file, std::filesystem::path tum_file, std::optional<Pose> velo_to_cam);
  /// Appends one pose (LiDAR frame) and returns the pose written to the KITTI
  /// file; the first call creates the files (InputError when it cannot).
  Pose write(double timestamp, const Pose& lidar_pose);

 private:
  void open();

  std::filesystem::path kitti_file_, tum_file_;
  std::optional<Pose> velo_to_cam_;
  std::ofstream kitti_, tum_;
};

/// The KITTI-file poses of LiDAR-frame poses (camera convention when Tr is given).
std::vector<Pose> output_poses(const std::vector<Pose>& lidar_poses, const std::optional<Pose>& velo_to_cam);

}  // namespace saloam
