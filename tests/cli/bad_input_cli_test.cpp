// End-to-end: inputs that used to give plausible but wrong results (issue 13,
// "silent wrong results") stop with a message naming the file and the
// problem, and a non-zero exit. Every sequence here is a tiny one written by
// the test itself.

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "saloam/core/files.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "cli/cli_fixture.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::quoted;
using testing::run_command;
using testing::TempDir;

using testing::expect_has;
using testing::failure_of;
using testing::saloam_cmd;

/// SEQ with `frames` scans, poses.txt, times.txt and calib.txt.
fs::path write_sequence(const TempDir& tmp, std::size_t frames = 4) {
  return testing::write_street_sequence(tmp / "seq", frames);
}

TEST(BadInputCli, GapInScanNumbersStopsEveryCommandThatReadsASequence) {
  TempDir tmp;
  const fs::path seq = write_sequence(tmp);
  fs::remove(seq / "velodyne/000001.bin");
  const std::string s = quoted(seq);
  for (const std::string& args :
       {fmt::format("odom {} --out {}", s, quoted(tmp / "o")), fmt::format("slam {} --out {}", s, quoted(tmp / "s")),
        fmt::format("graph {} --frame 2 --out {}", s, quoted(tmp / "g.json")),
        fmt::format("render {} --out {}", s, quoted(tmp / "r")),
        fmt::format("place-eval {} --method scancontext --out {}", s, quoted(tmp / "p"))}) {
    const std::string output = failure_of(args);
    expect_has(output, "velodyne/000001.bin: missing scan");
  }
  EXPECT_FALSE(fs::exists(tmp / "o/poses.txt"));
  EXPECT_FALSE(fs::exists(tmp / "g.json"));

  fs::create_directories(seq / "velodyne/000001.bin");  // a folder named like the scan
  expect_has(failure_of(fmt::format("odom {} --out {}", s, quoted(tmp / "o"))), "000001.bin: is a directory");
}

std::size_t count_of(const std::string& text, const std::string& fragment) {
  std::size_t n = 0;
  for (auto at = text.find(fragment); at != std::string::npos; at = text.find(fragment, at + 1)) ++n;
  return n;
}

// Issue 24: a folder without calib.txt runs in the LiDAR frame, saying so
// once; --no-calib does the same when calib.txt is there.
TEST(BadInputCli, MissingCalibRunsInTheLidarFrameAndSaysSoOnce) {
  TempDir tmp;
  const fs::path seq = write_sequence(tmp);
  fs::remove(seq / "calib.txt");
  const std::string s = quoted(seq);
  const std::string said = "no calibration: pose files hold LiDAR-frame poses";
  std::string output;
  for (const std::string command : {"odom", "slam"}) {
    ASSERT_EQ(run_command(saloam_cmd(fmt::format("{} {} --out {}", command, s, quoted(tmp / command))), &output), 0)
        << output;
    EXPECT_EQ(count_of(output, said), 1u) << output;
    EXPECT_EQ(read_kitti_poses(tmp / command / "poses.txt").size(), 4u);
  }
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("place-eval {} --method scancontext --out {}", s, quoted(tmp / "p"))),
                        &output),
            0)
      << output;

  // With calib.txt (a quarter turn: the frames differ), camera-frame poses;
  // --no-calib keeps the LiDAR frame. "  Tr:" (indented) is read like "Tr:".
  std::ofstream(seq / "calib.txt") << "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n  Tr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n";
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("odom {} --out {}", s, quoted(tmp / "camera"))), &output), 0) << output;
  EXPECT_EQ(count_of(output, said), 0u) << output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("odom {} --out {} --no-calib", s, quoted(tmp / "lidar"))), &output), 0)
      << output;
  EXPECT_EQ(count_of(output, said), 1u) << output;
  const auto camera = read_kitti_poses(tmp / "camera/poses.txt"), lidar = read_kitti_poses(tmp / "lidar/poses.txt");
  ASSERT_EQ(camera.size(), lidar.size());
  Pose tr = Pose::Identity();
  tr.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  for (std::size_t i = 0; i < camera.size(); ++i) {
    EXPECT_LT((camera[i].matrix() - (tr * lidar[i] * tr.inverse()).matrix()).norm(), 1e-4) << i;
  }
}

TEST(BadInputCli, NonRigidCalibAndPosesAndBackwardTimesAreRejected) {
  TempDir tmp;
  const fs::path seq = write_sequence(tmp);
  const std::string s = quoted(seq);
  std::ofstream(seq / "calib.txt") << "Tr: 2 0 0 0 0 0.5 0 0 0 0 1 0\n";
  expect_has(failure_of(fmt::format("odom {} --out {}", s, quoted(tmp / "o"))),
             "calib.txt: line 1: rotation of 'Tr' is not orthonormal");
  std::ofstream(seq / "calib.txt") << "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n";

  std::ofstream(seq / "times.txt") << "0\n0.1\n0.3\n0.2\n";
  expect_has(failure_of(fmt::format("odom {} --out {}", s, quoted(tmp / "o"))),
             "times.txt: line 4: timestamp 0.2 is not after 0.3 on line 3");
  std::ofstream(seq / "times.txt") << "0\n0.1\n0.2\n0.3\n";

  std::ofstream(seq / "poses.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n2 0 0 0 0 0.5 0 0 0 0 1 0\n"
                                   << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0\n";
  expect_has(failure_of(fmt::format("eval --gt {} --est {}", quoted(seq / "poses.txt"), quoted(seq / "poses.txt"))),
             "poses.txt: line 2: rotation is not orthonormal");
}

TEST(BadInputCli, FailureAtTheFirstFrameLeavesNoPoseFile) {
  TempDir tmp;
  const fs::path seq = write_sequence(tmp);
  std::ofstream(seq / "velodyne/000000.bin", std::ios::trunc) << "1234567";  // truncated
  fs::create_directories(tmp / "o");
  for (const std::string command : {"odom", "slam"}) {
    std::ofstream(tmp / "o/poses.txt") << "an earlier run's poses\n";
    const std::string output = failure_of(fmt::format("{} {} --out {}", command, quoted(seq), quoted(tmp / "o")));
    expect_has(output, "000000.bin: size 7 bytes");
    EXPECT_FALSE(fs::exists(tmp / "o/poses.txt")) << command;
    EXPECT_FALSE(fs::exists(tmp / "o/poses_tum.txt")) << command;
    EXPECT_FALSE(fs::exists(tmp / "o/poses_odometry.txt")) << command;
  }
}

TEST(BadInputCli, OptionValuesAreCheckedWithReadableMessages) {
  TempDir tmp;
  const fs::path seq = write_sequence(tmp);
  std::string output;
  EXPECT_NE(run_command(saloam_cmd(fmt::format("graph {} --frame -1 --out {}", quoted(seq), quoted(tmp / "g.json"))),
                        &output),
            0);
  expect_has(output, "--frame");
  expect_has(output, "must be a whole number (0 or more), got '-1'");
  EXPECT_EQ(output.find("18446744073709551615"), std::string::npos) << output;

  EXPECT_NE(run_command(saloam_cmd(fmt::format("render {} --out {} --resolution 0", quoted(seq), quoted(tmp / "r"))),
                        &output),
            0);
  expect_has(output, "--resolution");
  expect_has(output, "must be a positive number, got '0'");
  EXPECT_LT(output.size(), 400u) << output;  // no 300-digit range
}

TEST(BadInputCli, CommandLineErrorsArePlainAndShort) {
  TempDir tmp;
  const fs::path seq = write_sequence(tmp);
  std::string output;
  const std::string huge(100'000, '7');
  EXPECT_NE(run_command(saloam_cmd(fmt::format("odom {} --out {} --frames {}", quoted(seq), quoted(tmp / "o"), huge)),
                        &output),
            0);
  expect_has(output, "--frames");
  expect_has(output, "more bytes)");
  EXPECT_LT(output.size(), 1000u);
  EXPECT_NE(run_command(saloam_cmd(fmt::format("odom {} --out {} --frames $(printf '1\\033[31m:3')", quoted(seq),
                                               quoted(tmp / "o"))),
                        &output),
            0);
  expect_has(output, "\\x1b[31m");
  EXPECT_EQ(output.find('\x1b'), std::string::npos) << output;
}

// A folder name that is not UTF-8 (any bytes but '/' and NUL are allowed)
// breaks no output: summary.json records it readably and exactly, and the
// viewer finds the sequence again from it.
TEST(BadInputCli, PathsThatAreNotUtf8BreakNoOutput) {
  TempDir tmp;
  const fs::path seq = write_sequence(tmp);
  const fs::path odd_seq = tmp / "seq\xff\xfe";
  fs::rename(seq, odd_seq);
  const fs::path out = tmp / "run\xff";
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {}", quoted(odd_seq), quoted(out))), &output), 0)
      << output;
  for (const char* name : {"summary.json", "map.ply", "view.html", "poses.txt"}) {
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name << "\n" << output;
  }
  std::ifstream summary_file(out / "summary.json");
  const auto summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["sequence_hex"], to_hex(fs::absolute(odd_seq).lexically_normal().string()));
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("view {} --out {}", quoted(out), quoted(tmp / "page.html"))), &output), 0)
      << output;
  EXPECT_EQ(output.find("no ground truth"), std::string::npos) << output;
  expect_has(output, "with ground truth");
}

TEST(BadInputCli, PathsAreNamedWithTheirProblem) {
  TempDir tmp;
  const fs::path seq = write_sequence(tmp);
  const std::string s = quoted(seq);
  // A folder where a file is expected.
  fs::create_directories(tmp / "folder.txt");
  expect_has(failure_of(fmt::format("eval --gt {} --est {}", quoted(tmp / "folder.txt"), quoted(seq / "poses.txt"))),
             "folder.txt: is a directory, not a file");
  // An output folder below a file: the path and the reason, no raw library text.
  std::ofstream(tmp / "plain_file") << "x";
  const std::string output = failure_of(fmt::format("odom {} --out {}", s, quoted(tmp / "plain_file/out")));
  expect_has(output, "plain_file/out: cannot create folder");
  EXPECT_EQ(output.find("filesystem error"), std::string::npos) << output;
  // graph --out creates its parent folders like the other commands.
  std::string graph_output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("graph {} --frame 1 --out {}", s, quoted(tmp / "a/b/g.json"))),
                        &graph_output),
            0)
      << graph_output;
  EXPECT_TRUE(fs::exists(tmp / "a/b/g.json"));
  // A byte-order mark at the start of poses.txt is skipped.
  const std::string poses = [&] {
    std::ifstream in(seq / "poses.txt");
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  std::ofstream(seq / "poses.txt") << "\xEF\xBB\xBF" << poses;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("eval --gt {} --est {}", quoted(seq / "poses.txt"), quoted(seq / "poses.txt"))),
                        &graph_output),
            0)
      << graph_output;
}

TEST(BadInputCli, EvalRefusesToMixLidarAndCameraFrames) {
  TempDir tmp;
  std::vector<Pose> lidar;
  Trajectory tum;
  for (int i = 0; i < 30; ++i) {
    Pose q = Pose::Identity();
    q.translation() = Eigen::Vector3d(1.0 * i, 0.05 * i * i / 30.0, 0);
    lidar.push_back(q);
    tum.timestamps.push_back(0.1 * i);
  }
  tum.poses = lidar;
  write_tum_trajectory(tmp / "est_tum.txt", tum);
  // KITTI ground truth in the camera frame: camera z = LiDAR x (KITTI's axes).
  Pose tr = Pose::Identity();
  tr.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  std::vector<Pose> camera;
  for (const auto& q : lidar) camera.push_back(tr * q * tr.inverse());
  write_kitti_poses(tmp / "gt.txt", camera);
  SequenceWriter(tmp / "seq").write_calib(tr);

  const std::string output = failure_of(fmt::format("eval --gt {} --est {}", quoted(tmp / "gt.txt"), quoted(tmp / "est_tum.txt")));
  expect_has(output, "est_tum.txt: TUM trajectory (LiDAR frame");
  expect_has(output, "--calib");
  std::string ok;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("eval --gt {} --est {} --calib {} --align none", quoted(tmp / "gt.txt"),
                                               quoted(tmp / "est_tum.txt"), quoted(tmp / "seq/calib.txt"))),
                        &ok),
            0)
      << ok;
  expect_has(ok, "ATE");

  std::ofstream(tmp / "reversed.txt") << "0.2 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 1\n0.3 2 0 0 0 0 0 1\n";
  expect_has(failure_of(fmt::format("eval --gt {} --est {}", quoted(tmp / "reversed.txt"), quoted(tmp / "est_tum.txt"))),
             "reversed.txt: line 2: timestamp 0.1 is not after 0.2");
}

}  // namespace
}  // namespace saloam
