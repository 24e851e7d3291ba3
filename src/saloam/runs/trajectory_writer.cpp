#include "saloam/runs/trajectory_writer.hpp"

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace saloam {

namespace {
Pose output_pose(const Pose& lidar_pose, const std::optional<Pose>& tr) {
  return tr ? orthonormalized(*tr * lidar_pose * tr->inverse()) : lidar_pose;
}
}  // namespace

TrajectoryWriter::TrajectoryWriter(const std::filesystem::path& kitti_file, const std::filesystem::path& tum_file,
                                   std::optional<Pose> velo_to_cam)
    : velo_to_cam_(std::move(velo_to_cam)), kitti_(kitti_file), tum_(tum_file) {
  if (!kitti_) throw InputError(kitti_file, "cannot write pose file");
  if (!tum_) throw InputError(tum_file, "cannot write pose file");
  tum_ << "# timestamp x y z qx qy qz qw (LiDAR frame, world = first scan)\n";
}

Pose TrajectoryWriter::write(double timestamp, const Pose& lidar_pose) {
  const Pose p = output_pose(lidar_pose, velo_to_cam_);
  kitti_ << kitti_pose_line(p) << '\n' << std::flush;
  tum_ << tum_pose_line(timestamp, lidar_pose) << '\n' << std::flush;
  return p;
}

std::vector<Pose> output_poses(const std::vector<Pose>& lidar_poses, const std::optional<Pose>& velo_to_cam) {
  std::vector<Pose> out;
  out.reserve(lidar_poses.size());
  for (const auto& q : lidar_poses) out.push_back(output_pose(q, velo_to_cam));
  return out;
}

void write_trajectory(const std::filesystem::path& kitti_file, const std::filesystem::path& tum_file,
                      const std::vector<double>& timestamps, const std::vector<Pose>& lidar_poses,
                      const std::optional<Pose>& velo_to_cam) {
  TrajectoryWriter writer(kitti_file, tum_file, velo_to_cam);
  for (std::size_t i = 0; i < lidar_poses.size(); ++i) writer.write(timestamps.at(i), lidar_poses[i]);
}

}  // namespace saloam
