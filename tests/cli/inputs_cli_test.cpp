// End-to-end: inputs that are not what they seem (issue 26). Absurd numbers
// stop the run naming the file (or are dropped with a count), a file that is
// a folder, a device or a FIFO is refused rather than taken for absent or
// waited on, a calibration that is a pose file is refused, a configuration
// says each key once, and an option bound to a configuration key is checked
// like --set.

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/place/sgpr_weights.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using namespace testing;

/// The shipped SGPR model with every value of `tensor` set to `value`, written
/// as it is (write_sgpr_weights would refuse it) to `file`.
fs::path write_model(const fs::path& file, const std::string& tensor, float value) {
  SgprWeights weights = read_sgpr_weights(source_dir() / "models/sgpr/saloam.sgw");
  if (tensor.empty()) {
    for (auto& [name, t] : weights.tensors) std::fill(t.values.begin(), t.values.end(), value);
  } else {
    weights.tensors.at(tensor).values[5] = value;
  }
  const auto bytes = serialize_sgpr_weights(weights);
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                              static_cast<std::streamsize>(bytes.size()));
  return file;
}

/// `saloam ARGS` under a time limit: a run that never ends fails the test
/// (exit 124) instead of hanging the suite.
std::string bounded_failure_of(const std::string& args) {
  std::string output;
  EXPECT_EQ(run_command("timeout 120 " + saloam_cmd(args), &output), 2) << args << "\n" << output;
  return output;
}

TEST(InputsCli, AbsurdModelWeightsAndGraphCentresStopTheRunNamingTheFile) {
  TempDir tmp;
  const fs::path seq = write_street_sequence(tmp / "seq", 6);
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("graph {} --frame 1 --out {}", quoted(seq), quoted(tmp / "g.json"))),
                        &output),
            0)
      << output;
  const fs::path absurd = write_model(tmp / "absurd.sgw", "dgcnn_s_conv1.0.weight", 3e38F);
  const fs::path huge = write_model(tmp / "huge.sgw", "", 0.9F * kMaxSgprWeight);  // each value in range, too large together
  const std::string graph = quoted(tmp / "g.json");

  // sgpr-score never prints nan with exit 0.
  output = bounded_failure_of(fmt::format("sgpr-score --model {} {} {}", quoted(absurd), graph, graph));
  expect_has(output, absurd.string() + ": tensor 'dgcnn_s_conv1.0.weight' holds 3e+38 at element 5");
  output = bounded_failure_of(fmt::format("sgpr-score --model {} {} {}", quoted(huge), graph, graph));
  expect_has(output, huge.string() + ": the SGPR network overflows");
  EXPECT_EQ(output.find("nan"), std::string::npos) << output;
  std::ofstream(tmp / "far.json") << R"({"nodes": [1, 2], "centers": [[0, 1e308, 0], [1, 1, 1]]})";
  expect_has(bounded_failure_of(fmt::format("sgpr-score {} {}", graph, quoted(tmp / "far.json"))),
             (tmp / "far.json").string() + ": semantic graph: centers[0] = 1e+308 is beyond +-100000");

  // place-eval ends (it once looped for ever on NaN scores), and so does slam with the hybrid detector.
  for (const fs::path& model : {absurd, huge}) {
    expect_has(bounded_failure_of(fmt::format("place-eval {} --method hybrid --exclude 1 --model {} --out {}",
                                              quoted(seq), quoted(model), quoted(tmp / "pe"))),
               model.string() + ": ");
    expect_has(bounded_failure_of(fmt::format("slam {} --detector hybrid --model {} --no-map --out {}", quoted(seq),
                                              quoted(model), quoted(tmp / "slam"))),
               model.string() + ": ");
  }
  EXPECT_FALSE(fs::exists(tmp / "pe/pr_curve.csv"));
  EXPECT_FALSE(fs::exists(tmp / "slam/summary.json"));
}

TEST(InputsCli, PointsFarBeyondAnyLidarAreDroppedWithACount) {
  TempDir tmp;
  const fs::path seq = write_street_sequence(tmp / "seq", 4);
  LabelledCloud scan = read_scan(seq / "velodyne/000002.bin", seq / "labels/000002.label");
  const std::size_t n = scan.size();
  for (std::size_t i = 0; i < 40; ++i) scan.push_back({1e30F, 0.0F, 1.0F}, 0.3F, cls::kPole, 0);
  write_scan_bin(seq / "velodyne/000002.bin", scan);
  write_scan_labels(seq / "labels/000002.label", scan);
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("odom {} --out {}", quoted(seq), quoted(tmp / "out"))), &output), 0)
      << output;
  expect_has(output, fmt::format("000002.bin: dropped 40 of {} points with a coordinate beyond 10000 m", n + 40));
}

TEST(InputsCli, FilesThatAreNotWhatTheySeemAreRefused) {
  TempDir tmp;
  const fs::path seq = write_street_sequence(tmp / "seq", 4);
  const std::string odom = fmt::format("odom {} --out {}", quoted(seq), quoted(tmp / "out"));

  // A calib.txt that is a copy of poses.txt: no Tr, and many lines of 12 numbers.
  fs::copy_file(seq / "poses.txt", seq / "calib.txt", fs::copy_options::overwrite_existing);
  expect_has(failure_of(odom), (seq / "calib.txt").string() + ": no 'Tr:' line, and 4 lines of 12 numbers: a pose file");
  write_street_sequence(tmp / "seq", 4);

  // poses.txt that is a folder, times.txt that is a link to /dev/zero: errors, not "absent".
  fs::rename(seq / "poses.txt", tmp / "poses.txt");
  fs::create_directory(seq / "poses.txt");
  expect_has(failure_of(odom), (seq / "poses.txt").string() + ": is a directory");
  fs::remove(seq / "poses.txt");
  fs::rename(tmp / "poses.txt", seq / "poses.txt");
  fs::remove(seq / "times.txt");
  fs::create_symlink("/dev/zero", seq / "times.txt");
  expect_has(failure_of(odom), (seq / "times.txt").string() + ": is not a regular file");
  EXPECT_FALSE(fs::exists(tmp / "out/poses.txt"));

  // A configuration that is a device or a FIFO is refused at once (no
  // writer ever opens the FIFO: reading it would wait for ever).
  expect_has(bounded_failure_of("config --config /dev/zero"), "/dev/zero: is not a regular file");
  ASSERT_EQ(::mkfifo((tmp / "fifo.yaml").c_str(), 0600), 0);
  expect_has(bounded_failure_of("config --config " + quoted(tmp / "fifo.yaml")), "fifo.yaml: is not a regular file");

  // A key given twice, a section given twice, a second document.
  std::ofstream(tmp / "twice.yaml") << "odometry:\n  threads: 2\nloop:\n  sigma: 0.02\nodometry:\n  threads: 3\n";
  expect_has(failure_of("config --config " + quoted(tmp / "twice.yaml")),
             "twice.yaml: 'odometry' is given twice (lines 1 and 5)");
  std::ofstream(tmp / "two.yaml") << "odometry:\n  threads: 2\n---\nodometry:\n  threads: 3\n";
  expect_has(failure_of("config --config " + quoted(tmp / "two.yaml")), "two.yaml: holds 2 YAML documents");
}

TEST(InputsCli, AnOptionBoundToAConfigurationKeyIsCheckedLikeSet) {
  TempDir tmp;
  const fs::path seq = write_street_sequence(tmp / "seq", 3);
  const std::string by_set = failure_of(fmt::format("bench {} --set threads=-1", quoted(seq)));
  const std::string by_option = failure_of(fmt::format("bench {} --threads -1", quoted(seq)));
  expect_has(by_set, "odometry.threads");
  expect_has(by_option, "--threads -1: ");
  // The same rule, word for word, after the origin.
  const auto rule = [](const std::string& text) { return text.substr(text.find("odometry.threads")); };
  EXPECT_EQ(rule(by_option), rule(by_set));
}

// An error quoting the input stays short and plain: a 10 MB line is cut, a
// NUL byte does not end the message.
TEST(InputsCli, ErrorsQuotingTheInputAreShortAndPlain) {
  TempDir tmp;
  std::ofstream(tmp / "big.txt") << "1 2 3 " << std::string(10'000'000, 'x') << "\n";
  std::string output = failure_of(fmt::format("eval --gt {} --est {}", quoted(tmp / "big.txt"), quoted(tmp / "big.txt")));
  expect_has(output, "big.txt: line 1: ");
  EXPECT_LT(output.size(), 2000u);
  std::ofstream(tmp / "nul.txt", std::ios::binary)
      << std::string("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0\0secret 0 1 0 0 0 0 1 0\n", 55);
  output = failure_of(fmt::format("eval --gt {} --est {}", quoted(tmp / "nul.txt"), quoted(tmp / "nul.txt")));
  expect_has(output, "\\x00secret");
}

// Option values are checked with short messages: no 300-digit range, no -1
// wrapped to 18446744073709551615.
TEST(InputsCli, ViewerBudgetsAreCheckedWithShortMessages) {
  TempDir tmp;
  for (const std::string option : {"--max-points 0", "--max-points -1", "--scan-points -1", "--max-scan-points -1"}) {
    std::string output;
    EXPECT_NE(run_command(saloam_cmd(fmt::format("view {} {}", quoted(tmp / "run"), option)), &output), 0) << option;
    expect_has(output, option.substr(0, option.find(' ')));
    EXPECT_LT(output.size(), 300u) << output;
    EXPECT_EQ(output.find("18446744073709551615"), std::string::npos) << output;
  }
}

// Failures that are reported: a scan of one point fails its registration in
// odom and slam alike (warned, counted, in summary.json), and a scene that
// leaves directions unconstrained is reported as degenerate. The street
// scans have vertical poles and one wall but no ground: nothing fixes the
// height, the roll or the pitch.
TEST(InputsCli, RegistrationFailuresAndDegenerateFramesAreReportedByOdomAndSlam) {
  TempDir tmp;
  const fs::path seq = write_street_sequence(tmp / "seq", 7);
  {
    LabelledCloud one;
    one.has_labels = true;
    one.push_back({5.0F, 1.0F, 0.5F}, 0.3F, cls::kPole, 0);
    SequenceWriter(seq).write_scan(4, one);
  }
  for (const std::string command : {"odom", "slam"}) {
    const fs::path out = tmp / command;
    std::string output;
    ASSERT_EQ(run_command(saloam_cmd(fmt::format("{} {} --out {}", command, quoted(seq), quoted(out))), &output), 0)
        << output;
    expect_has(output, "frame 4: registration failed (");
    expect_has(output, "1 registration failures, 5 degenerate frames");
    // One warning per stretch of degenerate frames: 1-3, then 5-6 after the failure.
    expect_has(output, "frame 1: degenerate geometry: ");
    expect_has(output, "frame 5: degenerate geometry");
    EXPECT_EQ(output.find("frame 2: degenerate"), std::string::npos) << output;
    const auto summary = nlohmann::json::parse(file_text(out / "summary.json"));
    EXPECT_EQ(summary["registration_failures"], 1) << command;
    EXPECT_EQ(summary["degenerate_frames"], 5) << command;
  }
  // Off: no direction is called degenerate.
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("odom {} --out {} --set odometry.degeneracy_eigenvalue=0", quoted(seq),
                                               quoted(tmp / "off"))),
                        &output),
            0)
      << output;
  expect_has(output, "1 registration failures, 0 degenerate frames");
}

}  // namespace
}  // namespace saloam
