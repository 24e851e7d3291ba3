// End-to-end: `saloam info` on each kind of source, and on what is not one.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "saloam/io/pcd.hpp"
#include "saloam/sources/open_source.hpp"
#include "saloam/sources/sequence_writer.hpp"
#include "cli/cli_fixture.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using namespace testing;

std::string info(const fs::path& path, const std::string& extra = "") {
  return saloam_cmd("info ") + quoted(path) + " " + extra;
}

TEST(InfoCli, SaysWhatEachSourceHolds) {
  TempDir dir;
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd("simulate --out ") + quoted(dir / "seq") +
                            " --preset straight --frames 0:3 --beams 16 --azimuth-steps 600",
                        &output),
            0)
      << output;
  ASSERT_EQ(run_command(info(dir / "seq"), &output), 0) << output;
  EXPECT_NE(output.find("format:      semantickitti (detected)"), std::string::npos) << output;
  EXPECT_NE(output.find("frames:      3, 0.200 s"), std::string::npos) << output;
  EXPECT_NE(output.find("rate:        10.00 Hz"), std::string::npos) << output;
  EXPECT_NE(output.find("beams:       16 (points stored laser by laser)"), std::string::npos) << output;
  // 16 of the HDL-64E's lasers (--beams 16): still that sensor.
  EXPECT_NE(output.find("sensor:      hdl64e (Velodyne HDL-64E (KITTI)), guessed from the first scan: 16 lasers (points "
                        "stored laser by laser) from +2.0 to -23.3 deg, 16 of its 64 lasers"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("reference:   3 poses"), std::string::npos) << output;
  EXPECT_NE(output.find("calibration: calib.txt"), std::string::npos) << output;

  auto seq = open_reader(dir / "seq", {});
  SequenceWriteOptions pcd;
  pcd.format = ScanFormat::kPcd;
  pcd.pcd = PcdEncoding::kAscii;
  write_scan_sequence(*seq, dir / "pcd", pcd);
  fs::remove(dir / "pcd" / "calib.txt");
  ASSERT_EQ(run_command(info(dir / "pcd", "--scans 1"), &output), 0) << output;
  EXPECT_NE(output.find("format:      pcd (detected)"), std::string::npos) << output;
  EXPECT_NE(output.find("fields:      x y z intensity"), std::string::npos) << output;
  EXPECT_NE(output.find("calibration: none: runs in the LiDAR frame"), std::string::npos) << output;
  EXPECT_NE(output.find("point times: no"), std::string::npos) << output;
}

// A VLP-16 simulated into PCD files keeps each point's ring and time; info
// sees them and the sensor, and the odometry runs on them.
TEST(InfoCli, ASimulatedVlp16InPcdFilesHasRingsTimesAndItsSensor) {
  TempDir dir;
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd("simulate --out ") + quoted(dir / "vlp") +
                            " --preset straight --frames 0:4 --sensor vlp16 --azimuth-steps 900 --format pcd",
                        &output),
            0)
      << output;
  ASSERT_EQ(run_command(info(dir / "vlp", "--scans 1"), &output), 0) << output;
  EXPECT_NE(output.find("fields:      x y z intensity ring time"), std::string::npos) << output;
  EXPECT_NE(output.find("beams:       16 (ring field)"), std::string::npos) << output;
  EXPECT_NE(output.find("sensor:      vlp16 (Velodyne VLP-16), guessed from the first scan: 16 lasers (ring field) "
                        "from +15.0 to -15.0 deg"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("point times: yes, spanning 0.09"), std::string::npos) << output;
  ASSERT_EQ(run_command(info(dir / "vlp", "--sensor os1-64"), &output), 0) << output;
  EXPECT_NE(output.find("sensor:      os1-64 (Ouster OS1-64), as given (--sensor os1-64)"), std::string::npos) << output;
  EXPECT_NE(run_command(info(dir / "vlp", "--sensor vlp99"), &output), 0);
  EXPECT_NE(output.find("--sensor vlp99: no such profile file, nor a shipped profile"), std::string::npos) << output;
  ASSERT_EQ(run_command(saloam_cmd("odom ") + quoted(dir / "vlp") + " --out " + quoted(dir / "odom"), &output), 0)
      << output;
  EXPECT_NE(output.find("sensor: vlp16 (Velodyne VLP-16), guessed"), std::string::npos) << output;
  EXPECT_NE(output.find("4 frames, 0 registration failures"), std::string::npos) << output;
}

// Rings against the sensor's lasers (issue #39): a VLP-16 has rings 0..15, so
// points of a ring 16 or beyond are dropped and counted once the profile is
// known, given or guessed, with the readers' warning; a frame of nothing but
// such points is an error naming the source and frame.
TEST(InfoCli, RingsBeyondTheSensorsLasersAreDroppedAndCounted) {
  TempDir dir;
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd("simulate --out ") + quoted(dir / "vlp") +
                            " --preset straight --frames 0:3 --sensor vlp16 --azimuth-steps 900 --format pcd",
                        &output),
            0)
      << output;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir / "vlp")) {
    if (e.path().extension() == ".pcd") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files.size(), 3u);
  DecodedCloud second = read_pcd(files[1]);
  const std::size_t n = second.cloud.size();
  for (std::size_t i = 0; i < 25; ++i) second.cloud.ring[i * 7] = static_cast<std::uint16_t>(16 + i % 3);  // 25 points
  write_pcd(files[1], second.cloud, PcdEncoding::kBinary);
  const std::string expected = fmt::format("frame 1: dropped 25 of {} points with a ring at or beyond the sensor's 16 "
                                           "lasers (0..15)", n);
  for (const std::string sensor : {"", "--sensor vlp16"}) {
    SCOPED_TRACE(sensor);
    ASSERT_EQ(run_command(saloam_cmd("odom ") + quoted(dir / "vlp") + " --out " + quoted(dir / "odom") + " " + sensor,
                          &output),
              0)
        << output;
    EXPECT_NE(output.find(expected), std::string::npos) << output;
    EXPECT_EQ(output.find("frame 0: dropped"), std::string::npos) << output;
  }
  // A 64-laser profile holds them all: nothing dropped.
  ASSERT_EQ(run_command(saloam_cmd("odom ") + quoted(dir / "vlp") + " --out " + quoted(dir / "odom64") +
                            " --sensor os1-64", &output),
            0)
      << output;
  EXPECT_EQ(output.find("dropped"), std::string::npos) << output;
  // Every point beyond: an error naming the frame.
  for (auto& r : second.cloud.ring) r = 40;
  write_pcd(files[1], second.cloud, PcdEncoding::kBinary);
  EXPECT_EQ(run_command(saloam_cmd("odom ") + quoted(dir / "vlp") + " --out " + quoted(dir / "odom2") +
                            " --sensor vlp16", &output),
            2)
      << output;
  EXPECT_NE(output.find(fmt::format("frame 1: every one of its {} points has a ring at or beyond the sensor's 16 "
                                    "lasers", n)),
            std::string::npos)
      << output;
}

TEST(InfoCli, WhatIsNotASourceIsAnErrorSayingWhy) {
  TempDir dir;
  fs::create_directories(dir / "empty");
  std::string output;
  EXPECT_EQ(run_command(info(dir / "empty"), &output), 2);
  EXPECT_NE(output.find("empty: no scans found: expected velodyne/*.bin (SemanticKITTI)"), std::string::npos) << output;
  EXPECT_NE(run_command(info(dir / "empty", "--format las"), &output), 0);
  EXPECT_NE(output.find("las"), std::string::npos) << output;
}

}  // namespace
}  // namespace saloam
