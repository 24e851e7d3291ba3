#include <gtest/gtest.h>

#include <fstream>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/io/ply.hpp"
#include "saloam/io/sequence.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

using testing::input_error_of;

LabelledCloud small_cloud(std::uint16_t cls, std::size_t n = 5) {
  LabelledCloud c;
  c.has_labels = true;
  for (std::size_t i = 0; i < n; ++i) c.push_back({1.0f + i, 2.0f, -1.7f}, 0.3f, cls, 1);
  return c;
}

/// A three-scan sequence with labels, poses, calib and times.
void write_sequence(const std::filesystem::path& root) {
  SequenceWriter w(root);
  for (std::size_t i = 0; i < 3; ++i) w.write_scan(i, small_cloud(40));
  std::vector<Pose> poses(3, Pose::Identity());
  poses[1].translation() = Eigen::Vector3d(0, 0, 1);
  poses[2].translation() = Eigen::Vector3d(0, 0, 2);
  w.write_camera_poses(poses);
  // KITTI's axes: camera x = -LiDAR y, camera y = -LiDAR z, camera z = LiDAR x.
  Pose velo_to_cam = Pose::Identity();
  velo_to_cam.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  w.write_calib(velo_to_cam);
  w.write_times({0.0, 0.1, 0.2});
}

TEST(Sequence, WriteThenRead) {
  testing::TempDir dir;
  write_sequence(dir.path());
  EXPECT_TRUE(std::filesystem::exists(dir / "velodyne/000002.bin"));
  EXPECT_TRUE(std::filesystem::exists(dir / "labels/000002.label"));
  const SequenceReader seq(dir.path());
  ASSERT_EQ(seq.size(), 3u);
  EXPECT_TRUE(seq.has_labels());
  EXPECT_TRUE(seq.has_poses());
  EXPECT_TRUE(seq.has_calib());
  EXPECT_DOUBLE_EQ(seq.times()[2], 0.2);
  const auto scan = seq.load_scan(1);
  EXPECT_EQ(scan.size(), 5u);
  EXPECT_EQ(scan.label[0], 40);
  // Camera z (forward) is LiDAR x (forward).
  EXPECT_NEAR(seq.lidar_poses()[2].translation().x(), 2.0, 0.05);
  EXPECT_EQ(frame_name(42), "000042");
}

TEST(Sequence, PredictionsFolderReplacesLabels) {
  testing::TempDir dir;
  write_sequence(dir.path());
  for (std::size_t i = 0; i < 3; ++i) write_scan_labels(dir / "pred" / (frame_name(i) + ".label"), small_cloud(70));
  const SequenceReader seq(dir.path(), SequenceOptions{dir / "pred", false});
  EXPECT_EQ(seq.load_scan(0).label[0], 70);
  const SequenceReader plain(dir.path(), SequenceOptions{std::nullopt, true});
  EXPECT_FALSE(plain.has_labels());
  EXPECT_EQ(plain.load_scan(0).label[0], 0);
}

TEST(Sequence, MissingPiecesGiveClearErrors) {
  testing::TempDir dir;
  EXPECT_NE(input_error_of([&] { SequenceReader s(dir / "nope"); }).find("sequence folder not found"),
            std::string::npos);
  EXPECT_NE(input_error_of([&] { SequenceReader s(dir.path()); }).find("missing velodyne/"), std::string::npos);
  std::filesystem::create_directories(dir / "velodyne");
  EXPECT_NE(input_error_of([&] { SequenceReader s(dir.path()); }).find("no .bin scans"), std::string::npos);

  write_sequence(dir.path());
  std::filesystem::remove(dir / "labels/000001.label");
  EXPECT_NE(input_error_of([&] { SequenceReader s(dir.path()); }).find("first missing: 000001.label"),
            std::string::npos);
  std::filesystem::remove_all(dir / "labels");

  std::filesystem::remove(dir / "calib.txt");
  const SequenceReader seq(dir.path());
  EXPECT_FALSE(seq.has_labels());
  EXPECT_NE(input_error_of([&] { (void)seq.lidar_poses(); }).find("missing calib.txt"), std::string::npos);
  EXPECT_NE(input_error_of([&] { SequenceReader s(dir.path(), SequenceOptions{dir / "preds", false}); })
                .find("labels folder not found"),
            std::string::npos);

  std::ofstream(dir / "times.txt") << "0\n0.1\n";
  EXPECT_NE(input_error_of([&] { SequenceReader s(dir.path()); }).find("2 timestamps for 3 scans"), std::string::npos);
  std::ofstream(dir / "times.txt") << "0\n0.1\n0.2\n";
  std::ofstream(dir / "poses.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n";
  EXPECT_NE(input_error_of([&] { SequenceReader s(dir.path()); }).find("poses.txt: line 2"), std::string::npos);
}

// Scan i is velodyne/i.bin: a gap must not shift the later scans onto the
// poses and timestamps of their predecessors.
TEST(Sequence, MissingScanNumberIsAnErrorNamingIt) {
  testing::TempDir dir;
  write_sequence(dir.path());
  SequenceWriter(dir.path()).write_scan(3, small_cloud(40));
  std::ofstream(dir / "times.txt") << "0\n0.1\n0.2\n0.3\n";
  std::filesystem::remove(dir / "velodyne/000001.bin");
  const auto msg = input_error_of([&] { SequenceReader s(dir.path()); });
  EXPECT_NE(msg.find("velodyne/000001.bin: missing scan"), std::string::npos) << msg;
  EXPECT_NE(msg.find("found 000002.bin next"), std::string::npos) << msg;

  std::filesystem::rename(dir / "velodyne/000002.bin", dir / "velodyne/000001.bin");
  std::filesystem::rename(dir / "velodyne/000003.bin", dir / "velodyne/000002.bin");
  std::filesystem::remove(dir / "velodyne/000000.bin");  // numbering must start at 000000
  EXPECT_NE(input_error_of([&] { SequenceReader s(dir.path()); }).find("000000.bin: missing scan"), std::string::npos);
}

TEST(Sequence, EntriesNamedLikeScansMustBeNumberedFiles) {
  testing::TempDir dir;
  write_sequence(dir.path());
  std::filesystem::create_directories(dir / "velodyne/000003.bin");
  auto msg = input_error_of([&] { SequenceReader s(dir.path()); });
  EXPECT_NE(msg.find("000003.bin: is a directory, not a scan file"), std::string::npos) << msg;
  std::filesystem::remove(dir / "velodyne/000003.bin");

  write_scan_bin(dir / "velodyne/scan.bin", small_cloud(40));
  msg = input_error_of([&] { SequenceReader s(dir.path()); });
  EXPECT_NE(msg.find("scan.bin: scan names must be frame numbers"), std::string::npos) << msg;
  std::filesystem::remove(dir / "velodyne/scan.bin");

  write_scan_bin(dir / "velodyne/2.bin", small_cloud(40));
  msg = input_error_of([&] { SequenceReader s(dir.path()); });
  EXPECT_NE(msg.find("same frame number as"), std::string::npos) << msg;
  std::filesystem::remove(dir / "velodyne/2.bin");

  std::ofstream(dir / "velodyne/notes.txt") << "other files are ignored\n";
  EXPECT_EQ(SequenceReader(dir.path()).size(), 3u);
  msg = input_error_of([&] { SequenceReader s(dir / "times.txt"); });
  EXPECT_NE(msg.find("times.txt: is not a folder (expected a sequence folder)"), std::string::npos) << msg;
}

// Documented: more times/poses lines than scans is a sequence holding only
// its first scans (the first lines are used); fewer is an error.
TEST(Sequence, ExtraTimesAndPosesLinesBelongToScansNotPresent) {
  testing::TempDir dir;
  write_sequence(dir.path());
  std::filesystem::remove(dir / "velodyne/000002.bin");
  std::filesystem::remove(dir / "labels/000002.label");
  const SequenceReader seq(dir.path());
  ASSERT_EQ(seq.size(), 2u);
  EXPECT_EQ(seq.times().size(), 2u);
  ASSERT_EQ(seq.camera_poses().size(), 2u);
  EXPECT_NEAR(seq.camera_poses()[1].translation().z(), 1.0, 1e-9);

  std::ofstream(dir / "times.txt") << "0\n0.2\n0.1\n";
  const auto msg = input_error_of([&] { SequenceReader s(dir.path()); });
  EXPECT_NE(msg.find("times.txt: line 3: timestamp 0.1 is not after 0.2"), std::string::npos) << msg;
}

TEST(Ply, BinaryRoundTripWithColoursAndTransform) {
  testing::TempDir dir;
  auto cloud = small_cloud(50, 100);
  cloud.instance[7] = 321;
  Pose shift = Pose::Identity();
  shift.translation() = Eigen::Vector3d(10, 0, 0);
  write_ply(dir / "c.ply", cloud, shift);
  std::ifstream in(dir / "c.ply", std::ios::binary);
  std::string header((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(header.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(header.find("element vertex 100\n"), std::string::npos);
  EXPECT_NE(header.find("property uchar red\n"), std::string::npos);
  const auto back = read_ply(dir / "c.ply");
  ASSERT_EQ(back.size(), 100u);
  EXPECT_NEAR(back.points[3].x(), cloud.points[3].x() + 10.0f, 1e-5);
  EXPECT_EQ(back.label[3], 50);
  EXPECT_EQ(back.instance[7], 321);
  EXPECT_FLOAT_EQ(back.remission[3], 0.3f);
  // Size: header + 23 bytes per vertex.
  const auto body = std::filesystem::file_size(dir / "c.ply") - (header.find("end_header\n") + 11);
  EXPECT_EQ(body, 100u * 23u);
}

}  // namespace
}  // namespace saloam
