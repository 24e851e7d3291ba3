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

TrajectoryWriter::TrajectoryWriter(std::filesystem::path kitti_file, std::filesystem::path tum_file,
                                   std::optional<Pose> velo_to_cam)
    : kitti_file_(std::move(kitti_file)), tum_file_(std::move(tum_file)), velo_to_cam_(std::move(velo_to_cam)) {
  for (const auto* file : {&kitti_file_, &tum_file_}) {
    std::error_code ec;
    std::filesystem::remove(*file, ec);
    if (ec) throw InputError(*file, "cannot replace the pose file of an earlier run: " + ec.message());
  }
}

void TrajectoryWriter::open() {
  kitti_.open(kitti_file_);
  if (!kitti_) throw InputError(kitti_file_, "cannot write pose file");
  tum_.open(tum_file_);
  if (!tum_) throw InputError(tum_file_, "cannot write pose file");
  tum_ << "# timestamp x y z qx qy qz qw (LiDAR frame, world = first scan)\n";
}

Pose TrajectoryWriter::write(double timestamp, const Pose& lidar_pose) {
  if (!kitti_.is_open()) open();
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

}  // namespace saloam
