// The real KITTI drive (../shared/data/kitti_raw_0005, issue 24): its first 30 scans
// unpacked as a SemanticKITTI folder, then written by `saloam convert` as a
// KITTI raw drive (oxts from the reference poses) and as a folder of
// binary_compressed PCD files. The three readers agree on every scan, time
// and reference pose, and `saloam odom` and `saloam slam` give the same poses
// from each (the first 20 frames, to keep the suite fast; docs/real_sensors.md
// has the whole drive).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "saloam/io/pcd.hpp"
#include "saloam/sources/open_source.hpp"
#include "saloam/sources/sequence_summary.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::quoted;
using testing::run_command;

std::string saloam_cmd(const std::string& args) { return quoted(testing::cli_path()) + " " + args; }

std::string file_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The first scans of the drive, enough for the runs' 20 frames and small on disk (each layout holds a copy).
constexpr int kScans = 30;

/// The first `count` lines of `file`, each with its newline.
std::string first_lines(const fs::path& file, int count) {
  std::ifstream in(file);
  std::string text, line;
  for (int i = 0; i < count && std::getline(in, line); ++i) text += line + "\n";
  return text;
}

/// The first kScans scans of the drive as a KITTI folder in `dir`/kitti, with their poses, times and calib.txt.
fs::path unpack_kitti_folder(const fs::path& dir) {
  const fs::path kitti = dir / "kitti";
  fs::create_directories(kitti);
  const fs::path data = testing::shared_file("data/kitti_raw_0005/velodyne_000000-000099.tar.xz");
  std::string members;
  for (int i = 0; i < kScans; ++i) members += fmt::format(" velodyne/{:06d}.bin", i);
  EXPECT_EQ(run_command(fmt::format("tar -xJf {} -C {}{}", quoted(data), quoted(kitti), members)), 0);
  for (const char* name : {"poses.txt", "times.txt"}) {
    const fs::path whole = testing::shared_file(std::string("data/kitti_raw_0005/") + name);
    std::ofstream(kitti / name) << first_lines(whole, kScans);
  }
  fs::copy_file(testing::shared_file("data/kitti_raw_0005/calib.txt"), kitti / "calib.txt");
  return kitti;
}

void expect_same_source(FrameSource& source, FrameSource& other) {
  ASSERT_EQ(other.size(), source.size());
  for (std::size_t i = 0; i < source.size(); ++i) EXPECT_EQ(other.info().times[i], source.info().times[i]) << i;
  const auto reference = *source.info().camera_poses;  // Tr is the identity: LiDAR frame
  const auto poses = *other.info().camera_poses;
  for (std::size_t i = 0; i < poses.size(); ++i) ASSERT_LT((poses[i].matrix() - reference[i].matrix()).norm(), 1e-6) << i;
  for (std::size_t i = 0; i < source.size(); i += 3) {
    const LabelledCloud a = source.scan(i), b = other.scan(i);
    ASSERT_EQ(a.points, b.points) << i;
    ASSERT_EQ(a.remission, b.remission) << i;
  }
}

TEST(RealDriveCli, EveryLayoutGivesTheSameScansAndPoses) {
  SALOAM_REQUIRE_SHARED_DATA();
  testing::TempDir dir("saloam_real_drive");
  const fs::path kitti = unpack_kitti_folder(dir.path());
  const std::string encoding = pcd_compression_available() ? "binary_compressed" : "binary";
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("convert {} --out {} --to kitti-raw", quoted(kitti), quoted(dir / "drive"))), &output), 0) << output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("convert {} --out {} --to pcd --encoding {}", quoted(kitti), quoted(dir / "pcd"), encoding)), &output), 0) << output;

  auto source = open_reader(kitti, {});
  ASSERT_EQ(source->info().format, "semantickitti");
  ASSERT_EQ(source->size(), static_cast<std::size_t>(kScans));
  for (const fs::path& layout : {dir / "drive", dir / "pcd"}) {
    SCOPED_TRACE(layout.string());
    auto other = open_reader(layout, {});
    expect_same_source(*source, *other);
  }

  for (const std::string run : {"odom", "slam"}) {
    std::string poses;
    for (const fs::path& layout : {kitti, dir / "drive", dir / "pcd"}) {
      SCOPED_TRACE(run + " " + layout.string());
      const fs::path out = dir / (run + "_" + layout.filename().string());
      const std::string extra = run == "slam" ? " --detector scancontext --no-map" : "";
      ASSERT_EQ(run_command(saloam_cmd(fmt::format("{} {} --out {} --frames 0:20{}", run, quoted(layout), quoted(out), extra)), &output), 0) << output;
      const std::string text = file_text(out / "poses.txt");
      EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 20);
      if (poses.empty()) poses = text;
      EXPECT_EQ(text, poses) << "poses differ from the KITTI folder's";
    }
  }

  // What `saloam info` reports for the real drive: 64 beams, 10 Hz.
  auto drive = open_reader(dir / "drive", {});
  const SequenceSummary summary = summarize(*drive, 1);
  EXPECT_EQ(summary.format, "kitti-raw");
  EXPECT_NEAR(summary.median_interval, 0.1, 1e-9);
  ASSERT_TRUE(summary.lasers.has_value());
  EXPECT_EQ(summary.lasers->method, BeamMethod::kAzimuthWraps);
  EXPECT_EQ(summary.lasers->count(), 64u);
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("info {} --scans 1", quoted(dir / "drive"))), &output), 0) << output;
  EXPECT_NE(output.find("sensor:      hdl64e (Velodyne HDL-64E (KITTI)), guessed from the first scan: 64 lasers (points "
                        "stored laser by laser)"),
            std::string::npos)
      << output;
}

}  // namespace
}  // namespace saloam
