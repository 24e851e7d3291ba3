// open_source: the reader for a path, then the stages.

#include <gtest/gtest.h>

#include <algorithm>

#include "saloam/core/error.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/sources/open_source.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

/// A labelled five-scan sequence folder; calib.txt only when asked.
void write_sequence(const std::filesystem::path& root, bool calib) {
  SequenceWriter w(root);
  LabelledCloud cloud;
  cloud.has_labels = true;
  for (int i = 0; i < 4; ++i) cloud.push_back({1.0f + static_cast<float>(i), 2.0f, -1.7f}, 0.3f, 40, 0);
  for (std::size_t i = 0; i < 5; ++i) w.write_scan(i, cloud);
  w.write_camera_poses(std::vector<Pose>(5, Pose::Identity()));
  w.write_times({0.0, 0.1, 0.2, 0.3, 0.4});
  if (calib) w.write_calib(Pose::Identity());
}

TEST(OpenSource, OpensASequenceFolderWithItsLabelsAndCalibration) {
  testing::TempDir dir;
  write_sequence(dir.path(), true);
  const auto source = open_source(dir.path(), {});
  EXPECT_EQ(source->size(), 5u);
  EXPECT_EQ(source->info().first_frame, 0u);
  EXPECT_TRUE(source->info().has_labels);
  EXPECT_TRUE(source->info().velo_to_cam);
  EXPECT_TRUE(source->scan(4).has_labels);

  SourceOptions options;
  options.ignore_labels = true;
  options.ignore_calib = true;
  const auto plain = open_source(dir.path(), options);
  EXPECT_FALSE(plain->info().has_labels);
  EXPECT_FALSE(plain->info().velo_to_cam);
}

TEST(OpenSource, AppliesTheFrameRange) {
  testing::TempDir dir;
  write_sequence(dir.path(), true);
  SourceOptions options;
  options.frames = FrameRange::parse("2:4");
  const auto source = open_source(dir.path(), options);
  EXPECT_EQ(source->size(), 2u);
  EXPECT_EQ(source->info().first_frame, 2u);
  EXPECT_DOUBLE_EQ(source->info().times.front(), 0.2);
  EXPECT_EQ(source->info().folder, dir.path());
  options.frames = FrameRange::parse("5:");
  EXPECT_THROW((void)open_source(dir.path(), options), ConfigError);
}

TEST(OpenSource, AFolderWithoutCalibrationRunsInTheLidarFrame) {
  testing::TempDir dir;
  write_sequence(dir.path(), false);
  const auto source = open_source(dir.path(), {});
  EXPECT_EQ(source->size(), 5u);
  EXPECT_FALSE(source->info().velo_to_cam);
  EXPECT_TRUE(source->info().camera_poses);  // poses.txt, taken as LiDAR-frame poses
  const auto& notes = source->info().notes;
  EXPECT_NE(std::find(notes.begin(), notes.end(), "calibration: none (no calib.txt): runs in the LiDAR frame"),
            notes.end());
}

TEST(OpenSource, NamesTheFormatAndPicksTheReader) {
  testing::TempDir dir;
  write_sequence(dir / "seq", true);
  SourceOptions options;
  options.format = ScanFormat::kKittiRaw;
  EXPECT_NE(testing::input_error_of([&] { (void)open_reader(dir / "seq", options); })
                .find("velodyne_points/data: missing: a KITTI raw drive keeps its scans in velodyne_points/data/"),
            std::string::npos);
  options.format = ScanFormat::kSemanticKitti;
  const auto source = open_reader(dir / "seq", options);
  EXPECT_EQ(source->info().format, "semantickitti");
  EXPECT_EQ(source->info().point_fields, "x y z remission");
  EXPECT_EQ(scan_format_from_name("kitti-raw"), ScanFormat::kKittiRaw);
  EXPECT_FALSE(scan_format_from_name("las").has_value());
  EXPECT_EQ(format_name(ScanFormat::kRosbag), "rosbag");
  EXPECT_EQ(format_name(ScanFormat::kMcap), "mcap");
  EXPECT_EQ(format_name(ScanFormat::kPcap), "pcap");
  EXPECT_EQ(scan_format_names().size(), 9u);
}

}  // namespace
}  // namespace saloam
