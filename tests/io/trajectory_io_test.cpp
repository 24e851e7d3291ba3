#include <gtest/gtest.h>

#include <fstream>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

using testing::input_error_of;

std::vector<Pose> spiral(std::size_t n) {
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < n; ++i) {
    Vector6d xi;
    const double s = static_cast<double>(i);
    xi << 0.9 * s, 0.1 * s, -0.01 * s, 0.001 * s, -0.002 * s, 0.03 * s;
    poses.push_back(se3_exp(xi));
  }
  return poses;
}

void write_text(const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; }

TEST(TrajectoryIo, KittiRoundTrip) {
  testing::TempDir dir;
  const auto poses = spiral(50);
  write_kitti_poses(dir / "p.txt", poses);
  const auto back = read_kitti_poses(dir / "p.txt");
  ASSERT_EQ(back.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) EXPECT_TRUE(back[i].isApprox(poses[i], 1e-8)) << i;
  const auto traj = read_trajectory(dir / "p.txt");
  EXPECT_EQ(traj.size(), 50u);
  EXPECT_DOUBLE_EQ(traj.timestamps[10], 1.0);
}

TEST(TrajectoryIo, TumRoundTrip) {
  testing::TempDir dir;
  Trajectory t;
  t.poses = spiral(20);
  for (std::size_t i = 0; i < t.size(); ++i) t.timestamps.push_back(100.0 + 0.1 * static_cast<double>(i));
  write_tum_trajectory(dir / "t.txt", t);
  const auto back = read_tum_trajectory(dir / "t.txt");
  ASSERT_EQ(back.size(), t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_NEAR(back.timestamps[i], t.timestamps[i], 1e-6);
    EXPECT_TRUE(back.poses[i].isApprox(t.poses[i], 1e-7));
  }
  EXPECT_EQ(read_trajectory(dir / "t.txt").size(), t.size());
}

TEST(TrajectoryIo, ReadsSharedGroundTruth) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto poses = read_kitti_poses(testing::shared_file("data/kitti/poses/00.txt"));
  EXPECT_EQ(poses.size(), 4541u);
  EXPECT_TRUE(poses.front().isApprox(Pose::Identity(), 1e-6));
  const auto times = read_times(testing::shared_file("data/kitti/times/00.txt"));
  EXPECT_EQ(times.size(), 4541u);
}

TEST(TrajectoryIo, BadLinesNameTheLine) {
  testing::TempDir dir;
  write_text(dir / "bad.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n");
  auto msg = input_error_of([&] { read_kitti_poses(dir / "bad.txt"); });
  EXPECT_NE(msg.find("bad.txt: line 2: expected 12 numbers"), std::string::npos) << msg;

  write_text(dir / "junk.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 x 0 1 0 0 0 0 1 0\n");
  msg = input_error_of([&] { read_kitti_poses(dir / "junk.txt"); });
  EXPECT_NE(msg.find("line 2: 'x' is not a number"), std::string::npos) << msg;

  write_text(dir / "nan.txt", "1 0 0 nan 0 1 0 0 0 0 1 0\n");
  msg = input_error_of([&] { read_kitti_poses(dir / "nan.txt"); });
  EXPECT_NE(msg.find("line 1: non-finite"), std::string::npos) << msg;

  write_text(dir / "scaled.txt", "2 0 0 0 0 2 0 0 0 0 2 0\n");
  msg = input_error_of([&] { read_kitti_poses(dir / "scaled.txt"); });
  EXPECT_NE(msg.find("not orthonormal"), std::string::npos) << msg;

  write_text(dir / "empty.txt", "\n# nothing\n");
  msg = input_error_of([&] { read_kitti_poses(dir / "empty.txt"); });
  EXPECT_NE(msg.find("no poses"), std::string::npos) << msg;

  write_text(dir / "tum.txt", "0 1 2 3 0 0 0 1\n0.1 1 2 3 0 0 0\n");
  msg = input_error_of([&] { read_tum_trajectory(dir / "tum.txt"); });
  EXPECT_NE(msg.find("line 2: expected 8 numbers"), std::string::npos) << msg;

  write_text(dir / "mixed.txt", "0 1 2 3 0 0 0 1\n1 0 0 0 0 1 0 0 0 0 1 0\n");
  msg = input_error_of([&] { read_trajectory(dir / "mixed.txt"); });
  EXPECT_NE(msg.find("line 2"), std::string::npos) << msg;

  msg = input_error_of([&] { read_kitti_poses(dir / "absent.txt"); });
  EXPECT_NE(msg.find("absent.txt: file not found"), std::string::npos) << msg;
}

// The conversion camera <-> LiDAR frame is checked against the independent
// conversion of the official ground truth stored in shared/ (scans_00/poses_lidar.txt).
TEST(Calibration, CameraToLidarMatchesSharedReference) {
  SALOAM_REQUIRE_SHARED_DATA();
  const Pose tr = read_velo_to_cam(testing::shared_file("data/kitti/calib_velo_to_cam.txt"), 0);
  auto camera = read_kitti_poses(testing::shared_file("data/kitti/poses/00.txt"));
  camera.resize(6);
  const auto lidar = camera_to_lidar_poses(camera, tr);
  const auto reference = read_kitti_poses(testing::shared_file("data/kitti/scans_00/poses_lidar.txt"));
  ASSERT_EQ(reference.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_LT((lidar[i].translation() - reference[i].translation()).norm(), 1e-5) << i;
    EXPECT_LT(rotation_angle(lidar[i].inverse() * reference[i]), 1e-6) << i;
  }
  // LiDAR forward is x: the car drives ~0.86 m/frame along +x at the start of 00.
  EXPECT_NEAR(lidar[1].translation().x(), 0.86, 0.01);
  const auto camera_back = lidar_to_camera_poses(lidar, tr);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_TRUE(camera_back[i].isApprox(camera[i], 1e-9));
}

TEST(Calibration, ReadsKittiCalibFileAndReportsMissingTr) {
  SALOAM_REQUIRE_SHARED_DATA();
  testing::TempDir dir;
  const Pose tr = read_velo_to_cam(testing::shared_file("data/kitti/calib_velo_to_cam.txt"), 4);
  write_calib(dir / "calib.txt", tr);
  EXPECT_TRUE(read_velo_to_cam(dir / "calib.txt").isApprox(tr, 1e-10));
  write_text(dir / "noTr.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0 1\n");
  EXPECT_NE(input_error_of([&] { read_velo_to_cam(dir / "noTr.txt"); }).find("no 'Tr:' line"), std::string::npos);
  write_text(dir / "shortTr.txt", "Tr: 1 0 0 0 0 1 0 0 0 0 1\n");
  EXPECT_NE(input_error_of([&] { read_velo_to_cam(dir / "shortTr.txt"); }).find("line 1"), std::string::npos);
  EXPECT_NE(input_error_of([&] { read_velo_to_cam(dir / "none.txt"); }).find("not found"), std::string::npos);
  EXPECT_NE(input_error_of([&] { read_velo_to_cam(testing::shared_file("data/kitti/calib_velo_to_cam.txt"), 42); })
                .find("no line for sequence 42"),
            std::string::npos);
}

}  // namespace
}  // namespace saloam
