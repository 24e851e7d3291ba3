// End-to-end: `saloam demo` on a few frames of the built-in route, the main
// job of the README's first set-up command.

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::cli_path;
using testing::quoted;
using testing::run_command;
using testing::TempDir;

TEST(DemoCli, ShortRunWritesEveryOutputAndAReadableTable) {
  TempDir dir;
  const fs::path out = dir / "demo";
  std::string output;
  ASSERT_EQ(run_command(quoted(cli_path()) + " demo --out " + quoted(out) + " --frames 0:8 --beams 16", &output), 0)
      << output;
  for (const char* file : {"sequence/velodyne/000007.bin", "sequence/labels_gt/000007.label", "slam/poses.txt",
                           "slam/poses_odometry.txt", "slam/loops.csv", "slam/eval_slam.json", "slam/eval_odometry.png",
                           "slam/trajectories.png", "slam/map.ply", "slam/map.png", "odometry_baseline/poses.txt",
                           "eval_baseline.png"}) {
    EXPECT_TRUE(fs::exists(out / file)) << file;
  }
  EXPECT_NE(output.find("| SLAM: semantic odometry + loop closure |"), std::string::npos) << output;
  EXPECT_NE(output.find("| odometry, label-agnostic baseline |"), std::string::npos) << output;
  EXPECT_NE(output.find("loops: 0 accepted"), std::string::npos) << output;
  // Eight frames are far shorter than KITTI's 100 m segments: the KITTI
  // errors are undefined and shown as such, never as "nan".
  EXPECT_NE(output.find("| n/a | n/a |"), std::string::npos) << output;
  EXPECT_EQ(output.find("nan"), std::string::npos) << output;
}

}  // namespace
}  // namespace saloam
