// End-to-end: `saloam demo` on a few frames of the built-in route, the main
// job of the README's first set-up command.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "cli/cli_fixture.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using namespace testing;

TEST(DemoCli, ShortRunWritesEveryOutputAndAReadableTable) {
  TempDir dir;
  const fs::path out = dir / "demo";
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd("demo --out ") + quoted(out) + " --frames 0:8 --beams 16", &output), 0)
      << output;
  for (const char* file : {"slam/poses.txt",
                           "slam/poses_odometry.txt", "slam/loops.csv", "slam/eval_slam.json", "slam/eval_odometry.png",
                           "slam/trajectories.png", "slam/map.ply", "slam/map.png", "slam/view.html", "odometry_baseline/poses.txt",
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
  // The scans went from the simulator straight into the SLAM: none on disk.
  EXPECT_FALSE(fs::exists(out / "sequence")) << output;
}

TEST(DemoCli, KeepsTheSequenceWhenAskedAndReusesIt) {
  TempDir dir;
  const fs::path out = dir / "demo";
  const std::string demo = saloam_cmd("demo --out ") + quoted(out) + " --frames 0:6 --beams 16 --no-baseline";
  std::string output;
  ASSERT_EQ(run_command(demo + " --keep-sequence", &output), 0) << output;
  for (const char* file : {"sequence/velodyne/000005.bin", "sequence/labels/000005.label",
                           "sequence/labels_gt/000005.label", "sequence/poses.txt", "sequence/calib.txt"}) {
    EXPECT_TRUE(fs::exists(out / file)) << file;
  }
  EXPECT_FALSE(fs::exists(out / "odometry_baseline")) << output;
  const auto lines = [](const std::string& text) { return std::count(text.begin(), text.end(), '\n'); };
  EXPECT_EQ(lines(file_text(out / "slam/poses.txt")), 6);

  ASSERT_EQ(run_command(demo + " --reuse", &output), 0) << output;
  EXPECT_NE(output.find("reusing"), std::string::npos) << output;
  EXPECT_EQ(lines(file_text(out / "slam/poses.txt")), 6);

  // The kept sequence is reused only for the options it was simulated with.
  EXPECT_EQ(run_command(saloam_cmd("demo --out ") + quoted(out) + " --frames 0:6 --beams 32 --seed 5 --reuse",
                        &output),
            2)
      << output;
  EXPECT_NE(output.find("was simulated otherwise (beams: 16, asked for 32; seed: 1, asked for 5)"), std::string::npos)
      << output;
  EXPECT_EQ(run_command(saloam_cmd("demo --reuse --out ") + quoted(dir / "none"), &output), 2) << output;
  EXPECT_NE(output.find("holds no kept sequence; run the demo once with --keep-sequence"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "none/slam")) << output;
}

}  // namespace
}  // namespace saloam
