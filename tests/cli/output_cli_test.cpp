// End-to-end: exit code 0 means every output is complete and belongs to this
// run. A full disk fails the run naming the file, two runs never share a
// folder, an earlier run's files never pass for this run's, and summary.json
// says what was written and whether the run was interrupted.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using namespace testing;

/// Whether this machine lets a process mount a tmpfs in a user and mount
/// namespace of its own (util-linux unshare; Linux with user namespaces).
bool small_filesystems_available() {
  static const bool available = [] {
    TempDir probe;
    return run_command(fmt::format("unshare --user --map-root-user --mount sh -c 'mount -t tmpfs -o size=64k none {}'",
                                   quoted(probe.path()))) == 0;
  }();
  return available;
}

struct SmallFilesystemRun {
  int exit_code = -1;
  std::string output;
  std::vector<std::pair<std::string, std::uintmax_t>> files;  ///< what the folder held afterwards: name, bytes
};

/// Runs `saloam ARGS` with a fresh tmpfs of `kib` KiB mounted on `mount`
/// (only the command sees it), and lists the files left there.
SmallFilesystemRun run_on_small_filesystem(const fs::path& mount, int kib, const std::string& args) {
  const std::string script = fmt::format(
      "mount -t tmpfs -o size={}k none {m} && {{ {}; echo \"exit=$?\"; find {m} -type f -printf \"file %P %s\\n\"; }}",
      kib, saloam_cmd(args), fmt::arg("m", quoted(mount)));
  SmallFilesystemRun run;
  run_command(fmt::format("unshare --user --map-root-user --mount sh -c {}", testing::quoted(fs::path(script))),
              &run.output);
  std::istringstream lines(run.output);
  for (std::string line; std::getline(lines, line);) {
    if (line.starts_with("exit=")) run.exit_code = std::stoi(line.substr(5));
    std::istringstream words(line);
    std::string tag, name;
    std::uintmax_t bytes = 0;
    if (words >> tag >> name >> bytes && tag == "file") run.files.emplace_back(name, bytes);
  }
  return run;
}

TEST(OutputCli, AFullDiskFailsTheRunNamingTheFileAndLeavesNoPartialResult) {
  if (!small_filesystems_available()) GTEST_SKIP() << "cannot mount a tmpfs in a user namespace here (unshare)";
  TempDir tmp;
  const fs::path seq = write_street_sequence(tmp / "seq", 6);
  fs::create_directories(tmp / "disk");
  for (const auto& [command, kib] : {std::pair{"odom", 8}, std::pair{"slam", 16}, std::pair{"slam", 24}}) {
    const SmallFilesystemRun run =
        run_on_small_filesystem(tmp / "disk", kib, fmt::format("{} {} --out {}", command, quoted(seq), quoted(tmp / "disk/out")));
    EXPECT_EQ(run.exit_code, 2) << run.output;
    expect_has(run.output, (tmp / "disk/out").string());
    expect_has(run.output, "no space left on the device");
    EXPECT_EQ(run.output.find("wrote "), std::string::npos) << run.output;
    for (const auto& [name, bytes] : run.files) {
      EXPECT_GT(bytes, 0u) << command << ": " << name << " is empty\n" << run.output;
      EXPECT_FALSE(is_partial_output_name(fs::path(name).filename().string())) << name;
      EXPECT_NE(name, "out/summary.json") << "a failed run writes no summary";
    }
  }
}

TEST(OutputCli, ARunStopsAtOnceWhenAnotherHoldsTheFolder) {
  TempDir tmp;
  const fs::path seq = write_street_sequence(tmp / "seq", 4);
  fs::create_directories(tmp / "out");
  const int fd = ::open((tmp / "out/.saloam-run").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  const std::string record = fmt::format("saloam-run 1\ncommand slam\npid {}\n", ::getpid());  // a live process
  ASSERT_EQ(::write(fd, record.data(), record.size()), static_cast<ssize_t>(record.size()));
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  for (const std::string command : {"odom", "slam"}) {
    const std::string output = failure_of(fmt::format("{} {} --out {}", command, quoted(seq), quoted(tmp / "out")));
    expect_has(output, fmt::format("{}: another saloam run (slam, process {}) is writing this folder",
                                   (tmp / "out").string(), ::getpid()));
  }
  ::close(fd);
  EXPECT_FALSE(fs::exists(tmp / "out/poses.txt"));
}

TEST(OutputCli, TwoRunsStartedTogetherNeverMixTheirFiles) {
  TempDir tmp;
  const fs::path seq = write_street_sequence(tmp / "seq", 24);
  const std::string script =
      fmt::format("{} > {} 2>&1 & {} > {} 2>&1; first=$?; wait $!; echo \"exit $first $?\"",
                  saloam_cmd(fmt::format("slam {} --out {} --frames 0:8 --no-map", quoted(seq), quoted(tmp / "out"))),
                  quoted(tmp / "a.log"),
                  saloam_cmd(fmt::format("slam {} --out {} --frames 0:24 --no-map", quoted(seq), quoted(tmp / "out"))),
                  quoted(tmp / "b.log"));
  std::string output;
  run_command(script, &output);
  int a = -1, b = -1;
  ASSERT_EQ(std::sscanf(output.c_str(), "exit %d %d", &b, &a), 2) << output;
  const std::string logs = file_text(tmp / "a.log") + file_text(tmp / "b.log");
  for (const int code : {a, b}) EXPECT_TRUE(code == 0 || code == 2) << logs;
  if (a == 2 || b == 2) expect_has(logs, "another saloam run (slam, process");
  // Whichever ran last owns every file: the counts agree with its summary.
  const auto summary = nlohmann::json::parse(file_text(tmp / "out/summary.json"));
  const std::size_t frames = summary["frames"].get<std::size_t>();
  EXPECT_EQ(line_count(tmp / "out/poses.txt"), frames) << logs;
  EXPECT_EQ(line_count(tmp / "out/poses_odometry.txt"), frames) << logs;
  EXPECT_EQ(line_count(tmp / "out/poses_tum.txt"), frames) << logs;
}

TEST(OutputCli, ARunLeavesNoFileOfTheEarlierRunAndItsSummaryListsWhatItWrote) {
  TempDir tmp;
  const fs::path seq = write_street_sequence(tmp / "seq", 6);
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {}", quoted(seq), quoted(tmp / "out"))), &output), 0)
      << output;
  ASSERT_TRUE(fs::exists(tmp / "out/map.ply"));
  ASSERT_TRUE(fs::exists(tmp / "out/view.html"));
  std::ofstream(tmp / "out/notes.txt") << "the user's own file";
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {} --no-map", quoted(seq), quoted(tmp / "out"))), &output),
            0)
      << output;
  for (const char* stale : {"map.ply", "map.png", "view.html"}) EXPECT_FALSE(fs::exists(tmp / "out" / stale)) << stale;
  EXPECT_TRUE(fs::exists(tmp / "out/notes.txt"));
  const auto summary = nlohmann::json::parse(file_text(tmp / "out/summary.json"));
  EXPECT_FALSE(summary["interrupted"].get<bool>());
  std::set<std::string> listed;
  for (const auto& name : summary["files"]) listed.insert(name.get<std::string>());
  std::set<std::string> present;
  for (const auto& entry : fs::directory_iterator(tmp / "out")) present.insert(entry.path().filename().string());
  present.erase(".saloam-run");
  present.erase("notes.txt");
  EXPECT_EQ(listed, present);
  expect_has(output, "wrote " + (tmp / "out").string() + " (poses_odometry.txt, ");
  EXPECT_EQ(output.find("map.ply"), std::string::npos) << output;
}

TEST(OutputCli, CtrlCIsRecordedAndTheEarlierMapAndPageAreGone) {
  TempDir tmp;
  const fs::path seq = write_street_sequence(tmp / "seq", 400);
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {} --frames 0:4", quoted(seq), quoted(tmp / "out"))),
                        &output),
            0)
      << output;
  // Interrupted as soon as the frames are being processed (the pose files exist under their temporary names).
  const std::string script = fmt::format(
      "{} > {} 2>&1 & pid=$!; for i in $(seq 400); do ls {} 2>/dev/null | grep -q partial && break; sleep 0.02; done; "
      "kill -INT $pid; wait $pid; echo \"exit $?\"",
      saloam_cmd(fmt::format("slam {} --out {}", quoted(seq), quoted(tmp / "out"))), quoted(tmp / "run.log"),
      quoted(tmp / "out"));
  run_command(script, &output);
  const std::string log = file_text(tmp / "run.log");
  if (output.find("exit 0") != std::string::npos) GTEST_SKIP() << "the run ended before the signal";
  expect_has(output, "exit 130");
  for (const char* stale : {"map.ply", "map.png", "view.html"}) EXPECT_FALSE(fs::exists(tmp / "out" / stale)) << stale;
  const auto summary = nlohmann::json::parse(file_text(tmp / "out/summary.json"));
  EXPECT_TRUE(summary["interrupted"].get<bool>()) << log;
  const std::size_t frames = summary["frames"].get<std::size_t>();
  EXPECT_LT(frames, 400u);
  EXPECT_EQ(line_count(tmp / "out/poses.txt"), frames);
  EXPECT_NE(file_text(tmp / "out/.saloam-run").find("end interrupted"), std::string::npos);
}

}  // namespace
}  // namespace saloam

namespace saloam {
namespace {

namespace fs = std::filesystem;
using namespace testing;

TEST(InputsCli, EvalAndViewNeverOverwriteAnInput) {
  TempDir tmp;
  const fs::path seq = write_street_sequence(tmp / "seq", 4);
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {}", quoted(seq), quoted(tmp / "run"))), &output), 0)
      << output;
  const std::string gt = file_text(seq / "poses.txt"), est = file_text(tmp / "run/poses.txt");
  const std::string eval = fmt::format("eval --gt {} --est {}", quoted(seq / "poses.txt"), quoted(tmp / "run/poses.txt"));
  expect_has(failure_of(eval + " --json " + quoted(seq / "poses.txt")), "is the input --gt");
  expect_has(failure_of(eval + " --plot " + quoted(tmp / "run/../run/poses.txt")), "is the input --est");
  EXPECT_EQ(file_text(seq / "poses.txt"), gt);
  EXPECT_EQ(file_text(tmp / "run/poses.txt"), est);

  expect_has(failure_of(fmt::format("view {} --out {}", quoted(tmp / "run"), quoted(tmp / "run/poses.txt"))),
             "poses.txt: exists and is not a viewer page");
  EXPECT_EQ(file_text(tmp / "run/poses.txt"), est);
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("view {}", quoted(tmp / "run"))), &output), 0) << output;  // its own page

  // An output folder is never the sequence, nor any folder holding one.
  expect_has(failure_of(fmt::format("odom {} --out {}", quoted(seq), quoted(seq))), "is the input SEQ_DIR");
  expect_has(failure_of(fmt::format("slam {} --out {}", quoted(seq), quoted(tmp / "run/.." / "seq"))),
             "is the input SEQ_DIR");
}

TEST(InputsCli, SimulateReplacesAllOfAnEarlierSimulationAndNothingElse) {
  TempDir tmp;
  const std::string simulate = "simulate --preset straight --beams 16 --azimuth-steps 180 --out " + quoted(tmp / "sim");
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(simulate + " --frames 0:6 --labels noisy"), &output), 0) << output;
  ASSERT_TRUE(fs::exists(tmp / "sim/labels_gt/000005.label"));
  ASSERT_EQ(run_command(saloam_cmd(simulate + " --frames 0:3"), &output), 0) << output;
  std::size_t scans = 0;
  for (const auto& entry : fs::directory_iterator(tmp / "sim/velodyne")) scans += entry.path().extension() == ".bin";
  EXPECT_EQ(scans, 3u);
  EXPECT_FALSE(fs::exists(tmp / "sim/labels_gt/000000.label")) << "ground truth of the earlier, noisy simulation";
  EXPECT_EQ(line_count(tmp / "sim/poses.txt"), 3u);
  expect_has(file_text(tmp / "sim/simulation.yaml"), "frames: 0:3\n");

  // A sequence simulate did not write (real data, a copy) is never replaced.
  const fs::path real = write_street_sequence(tmp / "real", 4);
  expect_has(failure_of("simulate --preset straight --beams 16 --frames 0:2 --out " + quoted(real)),
             "holds a sequence or results that saloam simulate did not write");
  EXPECT_EQ(line_count(real / "poses.txt"), 4u);
}

TEST(InputsCli, EvalPairsARunsPosesWithTheGroundTruthOfTheirFrames) {
  TempDir tmp;
  std::vector<Pose> truth;
  double x = 0;
  for (int i = 0; i < 12; ++i) {
    Pose pose = Pose::Identity();
    pose.translation() = Eigen::Vector3d(x, 0.05 * i * i, 0);
    x += 0.5 + 0.3 * (i % 3);  // uneven steps: shifted pairs do not fit
    truth.push_back(pose);
  }
  write_kitti_poses(tmp / "seq/poses.txt", truth);
  std::vector<Pose> run(truth.begin() + 5, truth.end());
  const Pose rebase = run.front().inverse();
  for (Pose& pose : run) pose = rebase * pose;  // a run's world is its first frame
  write_kitti_poses(tmp / "run/poses.txt", run);
  std::ofstream(tmp / "run/summary.json") << R"({"first_frame": 5, "files": ["poses.txt", "summary.json"]})";
  const std::string eval = fmt::format("eval --gt {} --est {} --align none", quoted(tmp / "seq/poses.txt"),
                                       quoted(tmp / "run/poses.txt"));
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(eval), &output), 0) << output;
  expect_has(output, "pairing by frame: the estimate starts at frame 5, the ground truth at frame 0");
  expect_has(output, "| poses evaluated | 7 (ground truth 7, estimate 7) |");
  expect_has(output, "| ATE RMSE, unaligned | 0.000000 m |");
  // A summary that does not list the file does not speak for it.
  std::ofstream(tmp / "run/summary.json") << R"({"first_frame": 5, "files": ["poses_tum.txt"]})";
  ASSERT_EQ(run_command(saloam_cmd(eval), &output), 0) << output;
  EXPECT_EQ(output.find("pairing by frame"), std::string::npos) << output;
  EXPECT_EQ(output.find("| ATE RMSE, unaligned | 0.000000 m |"), std::string::npos) << output;
  std::ofstream(tmp / "run/summary.json") << R"({"first_frame": 50, "files": ["poses.txt"]})";
  expect_has(failure_of(eval), "poses.txt: 12 poses, none of them at frame 50 where the other trajectory starts");
}

}  // namespace
}  // namespace saloam
