#pragma once
// Writes a trajectory as it is computed, in the two formats every run emits:
//   KITTI (12 numbers a line): camera-frame convention of the ground truth,
//     P_i = Tr Q_i Tr^-1, so `saloam eval`, the KITTI devkit and evo compare it
//     with poses.txt directly; LiDAR-frame poses when no Tr is known
//   TUM (timestamp x y z qx qy qz qw): LiDAR-frame poses Q_i = T_L0<-Li
// The files are written under temporary names from the first pose on, each
// line flushed as it is written, and put in place by commit() when the run's
// frames are done (an interrupted run commits the frames it finished). A run
// that fails, or stops before its first frame, leaves no pose file that could
// be taken for a result. A live run's writer (`growing`) writes under the
// final names from the first pose on, so that another process can follow
// them as they grow; what it wrote stays (its frames cannot be read again).

#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "saloam/core/output_file.hpp"
#include "saloam/core/types.hpp"

namespace saloam {

class TrajectoryWriter {
 public:
  /// Nothing is created yet. `growing`: written in place (GrowingFile), else through AtomicFiles.
  TrajectoryWriter(std::filesystem::path kitti_file, std::filesystem::path tum_file, std::optional<Pose> velo_to_cam,
                   bool growing = false);
  /// Appends one pose (LiDAR frame) and returns the pose written to the KITTI
  /// file; the first call creates the temporary files (InputError when it
  /// cannot), every call checks its writes.
  Pose write(double timestamp, const Pose& lidar_pose);
  /// Puts both files in place (when a pose was written); InputError naming a
  /// file that could not be written.
  void commit();

 private:
  void open();

  std::filesystem::path kitti_file_, tum_file_;
  std::optional<Pose> velo_to_cam_;
  bool growing_ = false;
  std::unique_ptr<OutputFile> kitti_, tum_;
};

/// The KITTI-file poses of LiDAR-frame poses (camera convention when Tr is given).
std::vector<Pose> output_poses(const std::vector<Pose>& lidar_poses, const std::optional<Pose>& velo_to_cam);

}  // namespace saloam
