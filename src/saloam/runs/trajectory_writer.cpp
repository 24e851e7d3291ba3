#include "saloam/runs/trajectory_writer.hpp"

#include "saloam/core/lie.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace saloam {

namespace {
Pose output_pose(const Pose& lidar_pose, const std::optional<Pose>& tr) {
  return tr ? orthonormalized(*tr * lidar_pose * tr->inverse()) : lidar_pose;
}
}  // namespace

TrajectoryWriter::TrajectoryWriter(std::filesystem::path kitti_file, std::filesystem::path tum_file,
                                   std::optional<Pose> velo_to_cam, bool growing)
    : kitti_file_(std::move(kitti_file)),
      tum_file_(std::move(tum_file)),
      velo_to_cam_(std::move(velo_to_cam)),
      growing_(growing) {}

namespace {
std::unique_ptr<OutputFile> open_pose_file(const std::filesystem::path& file, bool growing) {
  if (growing) return std::make_unique<GrowingFile>(file);
  return std::make_unique<AtomicFile>(file);
}
}  // namespace

void TrajectoryWriter::open() {
  kitti_ = open_pose_file(kitti_file_, growing_);
  tum_ = open_pose_file(tum_file_, growing_);
  tum_->stream() << "# timestamp x y z qx qy qz qw (LiDAR frame, world = first scan)\n";
}

Pose TrajectoryWriter::write(double timestamp, const Pose& lidar_pose) {
  if (!kitti_) open();
  const Pose p = output_pose(lidar_pose, velo_to_cam_);
  kitti_->stream() << kitti_pose_line(p) << '\n';
  kitti_->flush();
  tum_->stream() << tum_pose_line(timestamp, lidar_pose) << '\n';
  tum_->flush();
  return p;
}

void TrajectoryWriter::commit() {
  if (!kitti_) return;
  kitti_->commit();
  tum_->commit();
}

std::vector<Pose> output_poses(const std::vector<Pose>& lidar_poses, const std::optional<Pose>& velo_to_cam) {
  std::vector<Pose> out;
  out.reserve(lidar_poses.size());
  for (const auto& q : lidar_poses) out.push_back(output_pose(q, velo_to_cam));
  return out;
}

}  // namespace saloam
