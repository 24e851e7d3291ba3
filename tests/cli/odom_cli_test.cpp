// End-to-end: `saloam odom` and `saloam bench` on the six real KITTI scans
// (shared/data/kitti/scans_00) laid out as a sequence folder.

#include <cstdio>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "saloam/core/lie.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

using testing::cli_path;
using testing::run_command;
using testing::shared_file;
using testing::quoted;
using testing::TempDir;

/// SEQ/velodyne/00000{0..5}.bin (symlinks), times.txt and, optionally, calib.txt.
void make_sequence(const std::filesystem::path& seq, bool with_calib) {
  std::filesystem::create_directories(seq / "velodyne");
  std::ofstream times(seq / "times.txt");
  for (int i = 0; i < 6; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.bin", i);
    std::filesystem::create_symlink(shared_file(std::string("data/kitti/scans_00/") + name), seq / "velodyne" / name);
    times << 0.1 * i << "\n";
  }
  if (with_calib) {
    write_calib(seq / "calib.txt", read_velo_to_cam(shared_file("data/kitti/calib_velo_to_cam.txt"), 0));
  }
}

TEST(OdomCli, WritesCameraFramePosesTumAndTiming) {
  SALOAM_REQUIRE_SHARED_DATA();
  TempDir dir;
  make_sequence(dir / "seq", true);
  std::string output;
  const int code = run_command(quoted(cli_path()) + " odom " + quoted(dir / "seq") + " --out " +
                                   quoted(dir / "out") + " --set odometry.features.pose_time_in_sweep=0.05",
                               &output);
  ASSERT_EQ(code, 0) << output;
  const auto camera = read_kitti_poses(dir / "out" / "poses.txt");
  const auto lidar = read_tum_trajectory(dir / "out" / "poses_tum.txt");
  ASSERT_EQ(camera.size(), 6u);
  ASSERT_EQ(lidar.size(), 6u);
  EXPECT_TRUE(camera[0].isApprox(Pose::Identity(), 1e-9));
  // poses.txt = Tr Q Tr^-1 of the LiDAR poses; the car drives forward: +z in the camera frame.
  const Pose tr = read_velo_to_cam(shared_file("data/kitti/calib_velo_to_cam.txt"), 0);
  const auto expected = lidar_to_camera_poses(lidar.poses, tr);
  for (int i = 0; i < 6; ++i) EXPECT_LT((camera[i].matrix() - expected[i].matrix()).norm(), 1e-6);
  EXPECT_GT(camera[5].translation().z(), 3.0);
  EXPECT_LT(std::abs(camera[5].translation().x()), 0.5);
  // Against the ICP reference (LiDAR frame): 5 frames of ~0.7 m.
  const auto icp = read_kitti_poses(shared_file("data/kitti/scans_00/relative_poses_icp.txt"));
  Pose reference = Pose::Identity();
  for (const auto& step : icp) reference = reference * step;
  EXPECT_LT((reference.translation() - lidar.poses[5].translation()).norm(), 0.1);

  std::ifstream timing_file(dir / "out" / "timing.json");
  const auto timing = nlohmann::json::parse(timing_file);
  EXPECT_EQ(timing["frames"].get<int>(), 6);
  EXPECT_GT(timing["hz_median"].get<double>(), 0.0);
  EXPECT_TRUE(timing["stages"].contains("features"));
  EXPECT_TRUE(timing["stages"].contains("registration"));
}

TEST(OdomCli, FrameRangeNoSemanticsAndNoCalib) {
  SALOAM_REQUIRE_SHARED_DATA();
  TempDir dir;
  make_sequence(dir / "seq", false);
  std::string output;
  const int code = run_command(quoted(cli_path()) + " odom " + quoted(dir / "seq") + " --out " +
                                   quoted(dir / "out") + " --frames 1:4 --no-semantics --no-calib",
                               &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("LiDAR-frame poses"), std::string::npos) << output;  // said so
  const auto poses = read_kitti_poses(dir / "out" / "poses.txt");
  ASSERT_EQ(poses.size(), 3u);
  // Without calib.txt the poses stay in the LiDAR frame: forward is +x.
  EXPECT_GT(poses[2].translation().x(), 1.0);
}

TEST(OdomCli, BadInputFailsWithMessage) {
  SALOAM_REQUIRE_SHARED_DATA();
  TempDir dir;
  std::string output;
  int code = run_command(quoted(cli_path()) + " odom " + quoted(dir / "missing") + " --out " +
                             quoted(dir / "out"),
                         &output);
  EXPECT_NE(code, 0);
  EXPECT_NE(output.find("missing"), std::string::npos) << output;
  make_sequence(dir / "seq", true);
  code = run_command(quoted(cli_path()) + " odom " + quoted(dir / "seq") + " --out " +
                         quoted(dir / "out") + " --frames 9:12",
                     &output);
  EXPECT_NE(code, 0);
  EXPECT_NE(output.find("--frames"), std::string::npos) << output;
}

TEST(BenchCli, PrintsFrequencyStagesAndMemory) {
  SALOAM_REQUIRE_SHARED_DATA();
  TempDir dir;
  make_sequence(dir / "seq", true);
  std::string output;
  const int code = run_command(quoted(cli_path()) + " bench " + quoted(dir / "seq") + " --frames 0:3", &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("frequency: median"), std::string::npos) << output;
  EXPECT_NE(output.find("worst frame"), std::string::npos) << output;
  EXPECT_NE(output.find("registration"), std::string::npos) << output;
  EXPECT_NE(output.find("peak memory"), std::string::npos) << output;
}

}  // namespace
}  // namespace saloam
