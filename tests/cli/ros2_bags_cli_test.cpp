// End-to-end: ROS 2 recordings (rosbag2 .db3 folders and .mcap files, issue
// 40). A short simulated sequence converted into each gives the same
// odometry poses, byte for byte, as the SemanticKITTI folder it came from
// (in the LiDAR frame, without labels: a recording of point clouds has
// neither calibration nor classes); `saloam info` lists the topics; a
// recording converts back into a SemanticKITTI folder with the same poses;
// the simulator writes both formats directly (with rings and per-point
// times, like its PCD files).

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "cli/cli_fixture.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using namespace testing;

constexpr const char* kSimulation = " --preset straight --frames 0:8 --beams 16 --azimuth-steps 600";

std::string odom_poses(const fs::path& source, const fs::path& out, const std::string& extra = "") {
  std::string output;
  EXPECT_EQ(run_command(saloam_cmd(fmt::format("odom {} --out {} --no-semantics{}", quoted(source), quoted(out), extra)), &output), 0)
      << output;
  return file_text(out / "poses.txt");
}

TEST(Ros2BagsCli, Db3AndMcapGiveTheFoldersPosesByteForByte) {
  TempDir dir("saloam_ros2_bags");
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd("simulate --out " + quoted(dir / "seq") + kSimulation), &output), 0) << output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("convert {} --out {} --to rosbag2", quoted(dir / "seq"), quoted(dir / "bag"))), &output), 0) << output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("convert {} --out {} --to mcap", quoted(dir / "seq"), quoted(dir / "scans.mcap"))), &output), 0) << output;
  EXPECT_TRUE(fs::exists(dir / "bag" / "metadata.yaml"));
  EXPECT_TRUE(fs::exists(dir / "bag" / "bag_0.db3"));

  const std::string folder = odom_poses(dir / "seq", dir / "odom_seq", " --no-calib");
  EXPECT_EQ(std::count(folder.begin(), folder.end(), '\n'), 8);
  EXPECT_EQ(odom_poses(dir / "bag", dir / "odom_bag"), folder) << "rosbag2 folder";
  EXPECT_EQ(odom_poses(dir / "bag" / "bag_0.db3", dir / "odom_db3"), folder) << ".db3 file alone";
  EXPECT_EQ(odom_poses(dir / "scans.mcap", dir / "odom_mcap"), folder) << ".mcap file";

  ASSERT_EQ(run_command(saloam_cmd("info " + quoted(dir / "scans.mcap") + " --scans 1"), &output), 0) << output;
  EXPECT_NE(output.find("format:      mcap (detected)"), std::string::npos) << output;
  EXPECT_NE(output.find("frames:      8, 0.700 s"), std::string::npos) << output;
  EXPECT_NE(output.find("topics: /points (sensor_msgs/msg/PointCloud2, 8 messages)"), std::string::npos) << output;
  EXPECT_NE(output.find("MCAP, indexed by its summary"), std::string::npos) << output;
  ASSERT_EQ(run_command(saloam_cmd("info " + quoted(dir / "bag") + " --scans 1"), &output), 0) << output;
  EXPECT_NE(output.find("format:      rosbag2 (detected)"), std::string::npos) << output;
  EXPECT_NE(output.find("storage: rosbag2 folder of bag_0.db3 (sqlite3)"), std::string::npos) << output;

  // Back into a SemanticKITTI folder: the same scans, the same poses.
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("convert {} --out {} --to semantickitti", quoted(dir / "scans.mcap"), quoted(dir / "back"))), &output), 0) << output;
  EXPECT_EQ(odom_poses(dir / "back", dir / "odom_back"), folder) << "converted back";
}

TEST(Ros2BagsCli, TheSimulatorWritesBothWithRingsAndTimes) {
  TempDir dir("saloam_ros2_sim");
  std::string output;
  for (const char* format : {"pcd", "rosbag2", "mcap"}) {
    const std::string out = std::string(format) == "mcap" ? "sim.mcap" : format;
    ASSERT_EQ(run_command(saloam_cmd(fmt::format("simulate --out {} --format {}{}", quoted(dir / out), format, kSimulation)), &output), 0) << output;
  }
  ASSERT_EQ(run_command(saloam_cmd("info " + quoted(dir / "sim.mcap") + " --scans 1"), &output), 0) << output;
  EXPECT_NE(output.find("fields:      x y z intensity ring time"), std::string::npos) << output;
  const std::string pcd = odom_poses(dir / "pcd", dir / "odom_pcd", " --no-calib");
  EXPECT_EQ(odom_poses(dir / "rosbag2", dir / "odom_rosbag2"), pcd);
  EXPECT_EQ(odom_poses(dir / "sim.mcap", dir / "odom_mcap"), pcd);
}

TEST(Ros2BagsCli, CorruptRecordingsStopWithTheFileNamed) {
  TempDir dir("saloam_ros2_bad");
  std::string output;
  std::ofstream(dir / "bad.mcap") << "\x89MCAP0\r\n" << std::string(100, 'x');
  EXPECT_NE(run_command(saloam_cmd("info " + quoted(dir / "bad.mcap")), &output), 0);
  EXPECT_NE(output.find("bad.mcap: corrupt MCAP file: "), std::string::npos) << output;
  std::ofstream(dir / "bad.db3") << "not a database at all, but long enough to be looked at by SQLite........";
  EXPECT_NE(run_command(saloam_cmd("info " + quoted(dir / "bad.db3")), &output), 0);
  EXPECT_NE(output.find("bad.db3: "), std::string::npos) << output;
}

}  // namespace
}  // namespace saloam
