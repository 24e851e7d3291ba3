// Scan sequences in every layout: format detection, opening, and the round
// trips of the Done-when (a simulated sequence written in each
// format reads back with the SemanticKITTI source's clouds, times and poses).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/pcd.hpp"
#include "saloam/io/rosbag_structure.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sources/kitti_raw_drive.hpp"
#include "saloam/sources/point_cloud_folder.hpp"
#include "saloam/sources/open_source.hpp"
#include "saloam/sources/rosbag_source.hpp"
#include "saloam/sources/sequence_summary.hpp"
#include "saloam/sources/sequence_writer.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::input_error_of;

/// A short simulated SemanticKITTI sequence (16 beams, coarse azimuth: cheap).
const fs::path& simulated_sequence() {
  static testing::TempDir dir("saloam_sources_sim");
  static const bool written = [] {
    SimulationOptions options;
    options.preset = "straight";
    options.end_frame = 4;
    options.beams = 16;
    options.azimuth_steps = 600;
    options.show_progress = false;
    simulate_sequence(options, dir / "seq");
    return true;
  }();
  (void)written;
  static const fs::path seq = dir / "seq";
  return seq;
}

/// Wraps a source and gives every scan rings and per-point times, as a
/// real driver's clouds have.
class WithPointFields final : public FrameSource {
 public:
  explicit WithPointFields(FrameSource& inner) : inner_(inner) {}
  [[nodiscard]] const SourceInfo& info() const override { return inner_.info(); }
  LabelledCloud scan(std::size_t i) override {
    LabelledCloud c = inner_.scan(i);
    c.ring.resize(c.size());
    c.time.resize(c.size());
    for (std::size_t k = 0; k < c.size(); ++k) {
      c.ring[k] = static_cast<std::uint16_t>(k % 16);
      c.time[k] = 0.1f * static_cast<float>(k) / static_cast<float>(c.size());
    }
    return c;
  }

 private:
  FrameSource& inner_;
};

std::unique_ptr<FrameSource> open(const fs::path& path, const SourceOptions& options = {}) {
  return open_reader(path, options);
}

SequenceWriteOptions layout(ScanFormat format) {
  SequenceWriteOptions o;
  o.format = format;
  return o;
}

SourceOptions on_topic(const std::string& topic) {
  SourceOptions o;
  o.topic = topic;
  return o;
}

void expect_same_scans(FrameSource& a, FrameSource& b, bool fields) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const LabelledCloud ca = a.scan(i), cb = b.scan(i);
    ASSERT_EQ(ca.size(), cb.size()) << i;
    for (std::size_t k = 0; k < ca.size(); ++k) {
      ASSERT_EQ(ca.points[k], cb.points[k]) << i << " " << k;
      ASSERT_EQ(ca.remission[k], cb.remission[k]) << i << " " << k;
    }
    if (fields) {
      ASSERT_TRUE(cb.has_rings() && cb.has_times()) << i;
      EXPECT_EQ(ca.ring, cb.ring);
      EXPECT_EQ(ca.time, cb.time);
    }
  }
}

void expect_same_times(const FrameSource& a, const FrameSource& b, double tolerance) {
  const auto &ta = a.info().times, &tb = b.info().times;
  ASSERT_EQ(ta.size(), tb.size());
  for (std::size_t i = 0; i < ta.size(); ++i) EXPECT_NEAR(ta[i], tb[i], tolerance) << i;
}

/// Reference poses of both in the LiDAR frame agree within `tolerance` [m, and rad-ish].
void expect_same_lidar_poses(const FrameSource& a, const FrameSource& b, double tolerance) {
  const auto lidar = [](const FrameSource& s) {
    const auto& poses = *s.info().camera_poses;
    return s.info().velo_to_cam ? camera_to_lidar_poses(poses, *s.info().velo_to_cam) : poses;
  };
  ASSERT_TRUE(a.info().camera_poses && b.info().camera_poses);
  const auto pa = lidar(a), pb = lidar(b);
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t i = 0; i < pa.size(); ++i) {
    EXPECT_LT((pa[i].matrix() - pb[i].matrix()).norm(), tolerance) << i;
  }
}

TEST(Sources, SemanticKittiFolderIsDetectedAndRead) {
  const auto seq = open(simulated_sequence());
  EXPECT_EQ(seq->info().format, "semantickitti");
  EXPECT_EQ(seq->size(), 4u);
  EXPECT_TRUE(seq->info().has_labels);
  EXPECT_TRUE(seq->info().velo_to_cam.has_value());
  EXPECT_EQ(seq->info().camera_poses->size(), 4u);
  EXPECT_GT(seq->scan(0).size(), 1000u);
}

TEST(Sources, DetectionSaysWhatItLookedFor) {
  testing::TempDir dir;
  fs::create_directories(dir / "empty");
  EXPECT_NE(input_error_of([&] { detect_scan_format(dir / "empty"); }).find("no scans found: expected velodyne/*.bin (SemanticKITTI)"), std::string::npos);
  EXPECT_NE(input_error_of([&] { detect_scan_format(dir / "nothing"); }).find("nothing: not found"), std::string::npos);
  std::ofstream(dir / "empty" / "a.pcd") << "x";
  std::ofstream(dir / "empty" / "b.ply") << "x";
  EXPECT_NE(input_error_of([&] { detect_scan_format(dir / "empty"); }).find("both .pcd and .ply files"), std::string::npos);
  std::ofstream(dir / "notes.txt") << "x";
  EXPECT_NE(input_error_of([&] { detect_scan_format(dir / "notes.txt"); }).find("not a scan source"), std::string::npos);
  std::ofstream(dir / "x.bag") << "#ROSBAG V1.2\n";
  EXPECT_EQ(detect_scan_format(dir / "x.bag"), ScanFormat::kRosbag);
  EXPECT_NE(input_error_of([&] { open(dir / "x.bag"); }).find("not a ROS 1 bag of format 2.0"), std::string::npos);
  if (!rosbag_available()) {  // a build without rosbag_storage says so
    std::ofstream(dir / "y.bag") << kRosbagMagic;
    EXPECT_NE(input_error_of([&] { open(dir / "y.bag"); }).find("not built into this saloam"), std::string::npos);
  }
}

TEST(Sources, EveryPcdEncodingRoundTrips) {
  auto source = open(simulated_sequence());
  WithPointFields with_fields(*source);
  testing::TempDir dir;
  for (const auto encoding : {PcdEncoding::kAscii, PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed}) {
    if (encoding == PcdEncoding::kBinaryCompressed && !pcd_compression_available()) continue;
    SCOPED_TRACE(static_cast<int>(encoding));
    const fs::path out = dir / fmt::format("pcd{}", static_cast<int>(encoding));
    write_scan_sequence(with_fields, out, [&] { auto o = layout(ScanFormat::kPcd); o.pcd = encoding; return o; }());
    auto back = open(out);
    EXPECT_EQ(back->info().format, "pcd");
    EXPECT_TRUE(back->info().has_labels);  // labels/ beside the scans
    expect_same_scans(with_fields, *back, true);
    expect_same_times(*source, *back, 1e-9);
    expect_same_lidar_poses(*source, *back, 1e-6);
    EXPECT_EQ(back->scan(1).label, source->scan(1).label);
  }
}

TEST(Sources, EveryPlyEncodingRoundTrips) {
  auto source = open(simulated_sequence());
  WithPointFields with_fields(*source);
  testing::TempDir dir;
  for (const auto encoding : {PlyEncoding::kAscii, PlyEncoding::kBinaryLittleEndian, PlyEncoding::kBinaryBigEndian}) {
    SCOPED_TRACE(static_cast<int>(encoding));
    const fs::path out = dir / fmt::format("ply{}", static_cast<int>(encoding));
    write_scan_sequence(with_fields, out, [&] { auto o = layout(ScanFormat::kPly); o.ply = encoding; return o; }());
    auto back = open(out);
    EXPECT_EQ(back->info().format, "ply");
    expect_same_scans(with_fields, *back, true);
    expect_same_times(*source, *back, 1e-9);
    expect_same_lidar_poses(*source, *back, 1e-6);
  }
}

TEST(Sources, KittiRawRoundTripsWithOxtsPoses) {
  auto source = open(simulated_sequence());
  testing::TempDir dir;
  write_scan_sequence(*source, dir / "drive", layout(ScanFormat::kKittiRaw));
  EXPECT_TRUE(fs::exists(dir / "drive/velodyne_points/data/0000000003.bin"));
  EXPECT_TRUE(fs::exists(dir / "drive/oxts/data/0000000003.txt"));
  auto back = open(dir / "drive");
  EXPECT_EQ(back->info().format, "kitti-raw");
  EXPECT_FALSE(back->info().velo_to_cam.has_value());
  expect_same_scans(*source, *back, false);
  expect_same_times(*source, *back, 1e-6);
  expect_same_lidar_poses(*source, *back, 1e-5);
  const auto facts = back->info().notes;
  EXPECT_TRUE(std::any_of(facts.begin(), facts.end(),
                          [](const std::string& f) { return f.find("in the LiDAR frame via") != std::string::npos; }));

  // Sweep bounds, when the drive has them.
  std::vector<double> start, end;
  for (const double t : source->info().times) {
    start.push_back(kKittiRawEpoch + t - 0.05);
    end.push_back(kKittiRawEpoch + t + 0.0495);
  }
  write_kitti_timestamps(dir / "drive/velodyne_points/timestamps_start.txt", start);
  write_kitti_timestamps(dir / "drive/velodyne_points/timestamps_end.txt", end);
  const KittiRawDrive drive(dir / "drive", {});
  ASSERT_TRUE(drive.sweep_durations().has_value());
  EXPECT_NEAR(drive.sweep_durations()->at(2), 0.0995, 1e-6);
  EXPECT_NEAR(drive.first_stamp(), kKittiRawEpoch, 1e-6);
}

TEST(Sources, KittiRawWithoutOxtsOrTimestamps) {
  testing::TempDir dir;
  auto source = open(simulated_sequence());
  write_scan_sequence(*source, dir / "drive", layout(ScanFormat::kKittiRaw));
  fs::remove_all(dir / "drive/oxts/data/0000000002.txt");
  auto fewer = open(dir / "drive");
  EXPECT_FALSE(fewer->info().camera_poses.has_value());
  const auto fewer_notes = fewer->info().notes;
  EXPECT_TRUE(std::any_of(fewer_notes.begin(), fewer_notes.end(),
                          [](const std::string& f) { return f.starts_with("reference: none: "); }));
  fs::remove_all(dir / "drive/velodyne_points/timestamps.txt");
  EXPECT_DOUBLE_EQ(open(dir / "drive")->info().times[3], 0.3);
  fs::remove(dir / "drive/velodyne_points/data/0000000002.bin");
  EXPECT_NE(input_error_of([&] { open(dir / "drive"); }).find("frame 3 follows 1: a scan is missing"), std::string::npos);
}

TEST(Sources, BagRoundTripsAndPicksItsTopic) {
  if (!rosbag_available()) GTEST_SKIP() << "built without rosbag_storage";
  auto source = open(simulated_sequence());
  WithPointFields with_fields(*source);
  testing::TempDir dir;
  write_scan_sequence(with_fields, dir / "a.bag", layout(ScanFormat::kRosbag));
  auto back = open(dir / "a.bag");
  EXPECT_EQ(back->info().format, "rosbag");
  expect_same_scans(with_fields, *back, true);
  expect_same_times(*source, *back, 1e-8);
  EXPECT_NE(back->info().name.find("(topic /points)"), std::string::npos);
  const auto topics = list_bag_topics(dir / "a.bag");
  ASSERT_EQ(topics.size(), 1u);
  EXPECT_EQ(topics[0].messages, 4u);
  EXPECT_NE(input_error_of([&] { open(dir / "a.bag", on_topic("/lidar")); }).find("no topic '/lidar'; the bag holds: /points (sensor_msgs/PointCloud2, 4 messages)"), std::string::npos);
}

TEST(Sources, BagWithTwoCloudTopicsNeedsOne) {
  if (!rosbag_available()) GTEST_SKIP() << "built without rosbag_storage";
  testing::TempDir dir;
  LabelledCloud cloud;
  cloud.push_back({1, 2, 3}, 0.5f);
  {
    PointCloud2BagWriter writer(dir / "two.bag", "/front", "front");
    writer.write(cloud, 10.0);
    writer.write(cloud, 10.05, "/rear");
    writer.write(cloud, 10.1);
  }
  EXPECT_NE(input_error_of([&] { open(dir / "two.bag"); })
                .find("2 sensor_msgs/PointCloud2 topics: pick one with --topic: /front (sensor_msgs/PointCloud2, 2 messages); /rear"),
            std::string::npos);
  EXPECT_EQ(open(dir / "two.bag", on_topic("/front"))->size(), 2u);
  std::ofstream(dir / "bad.bag") << std::string(kRosbagMagic) << "garbage after the magic";
  EXPECT_NE(input_error_of([&] { open(dir / "bad.bag"); }).find("bad.bag: corrupt ROS bag: record at byte 13: "), std::string::npos);
}

// rosbag_storage trusts a bag's lengths: a connection record claiming a
// 4 GB header made it allocate 4 GB (found by fuzz/rosbag_fuzz.cpp). The
// structure check rejects such a bag before rosbag reads it.
TEST(Sources, CorruptBagLengthsAreCaughtBeforeRosbag) {
  if (!rosbag_available()) GTEST_SKIP() << "built without rosbag_storage";
  testing::TempDir dir;
  LabelledCloud cloud;
  cloud.push_back({1, 2, 3}, 0.5f);
  {
    PointCloud2BagWriter writer(dir / "a.bag", "/points", "velodyne");
    writer.write(cloud, 10.0);
  }
  EXPECT_NO_THROW(check_rosbag_structure(dir / "a.bag"));
  std::string bytes;
  {
    std::ifstream in(dir / "a.bag", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto corrupt_at = [&](std::size_t at, std::uint32_t value) {
    std::string copy = bytes;
    std::memcpy(copy.data() + at, &value, 4);
    std::ofstream(dir / "b.bag", std::ios::binary) << copy;
    return input_error_of([&] { open(dir / "b.bag"); });
  };
  // The connection record after index_pos (the index starts with it).
  std::uint64_t index_pos = 0;
  const auto field = bytes.find("index_pos=");
  ASSERT_NE(field, std::string::npos);
  std::memcpy(&index_pos, bytes.data() + field + 10, 8);
  EXPECT_NE(corrupt_at(index_pos, 0xFFFFFFFFu).find(fmt::format("b.bag: corrupt ROS bag: record at byte {}: header of 4294967295 bytes runs past its end", index_pos)),
            std::string::npos);
  EXPECT_NE(corrupt_at(field + 10, 100).find("index_pos 100 is not the start of a record"), std::string::npos);
}

TEST(Sources, FolderWithoutCalibRunsInTheLidarFrame) {
  testing::TempDir dir;
  LabelledCloud cloud;
  cloud.push_back({1, 2, 3}, 0.5f);
  write_pcd(dir / "1317042145.100000.pcd", cloud, PcdEncoding::kAscii);
  write_pcd(dir / "1317042145.200000.pcd", cloud, PcdEncoding::kBinary);
  auto seq = open(dir.path());
  EXPECT_EQ(seq->info().format, "pcd");
  EXPECT_FALSE(seq->info().velo_to_cam.has_value());
  EXPECT_FALSE(seq->info().camera_poses.has_value());
  EXPECT_NEAR(seq->info().times[1], 1317042145.2, 1e-6);
  const auto notes = seq->info().notes;
  EXPECT_NE(std::find(notes.begin(), notes.end(), "calibration: none: runs in the LiDAR frame"), notes.end());
  EXPECT_NE(std::find(notes.begin(), notes.end(), "times: from the file names"), notes.end());
  // One file alone is a sequence of one scan.
  EXPECT_EQ(open(dir / "1317042145.100000.pcd")->size(), 1u);
}

TEST(Sources, WriterNeverOverwritesAnInput) {
  auto source = open(simulated_sequence());
  EXPECT_NE(input_error_of([&] { write_scan_sequence(*source, simulated_sequence(), layout(ScanFormat::kPcd)); })
                .find("exists and is not an empty folder"),
            std::string::npos);
}

TEST(Sources, SummaryOfASimulatedSequence) {
  auto seq = open(simulated_sequence());
  const SequenceSummary s = summarize(*seq, 2);
  EXPECT_EQ(s.format, "semantickitti");
  EXPECT_EQ(s.frames, 4u);
  EXPECT_NEAR(s.median_interval, 0.1, 1e-9);
  EXPECT_EQ(s.scans_read, 2u);
  EXPECT_EQ(s.fields, "x y z remission");
  ASSERT_TRUE(s.lasers.has_value());
  EXPECT_EQ(s.lasers->count(), 16u) << static_cast<int>(s.lasers->method);  // the simulator's 16 lasers
  EXPECT_TRUE(s.labels && s.calibration);
  EXPECT_EQ(s.reference_poses, 4u);
  WithPointFields with_fields(*seq);
  EXPECT_EQ(find_lasers(with_fields.scan(0)).method, BeamMethod::kRingField);
  EXPECT_EQ(find_lasers(with_fields.scan(0)).count(), 16u);
}

}  // namespace
}  // namespace saloam
