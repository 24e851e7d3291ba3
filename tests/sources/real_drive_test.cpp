// The real KITTI drive (../shared/data/kitti_raw_0005): its scans unpacked
// as a SemanticKITTI folder, then written as a KITTI raw drive (oxts from
// the reference poses) and as a folder of binary_compressed PCD files. The
// three readers must agree on every scan, time and reference pose.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include "saloam/io/calibration.hpp"
#include "saloam/io/pcd.hpp"
#include "saloam/sources/open_source.hpp"
#include "saloam/sources/sequence_summary.hpp"
#include "saloam/sources/sequence_writer.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

TEST(RealDrive, KittiRawAndPcdLayoutsReadLikeTheKittiFolder) {
  SALOAM_REQUIRE_SHARED_DATA();
  const fs::path data = testing::shared_file("data/kitti_raw_0005/velodyne_000000-000099.tar.xz");
  testing::TempDir dir("saloam_real_drive");
  const fs::path kitti = dir / "kitti";
  fs::create_directories(kitti);
  ASSERT_EQ(testing::run_command(fmt::format("tar -xJf {} -C {}", testing::quoted(data), testing::quoted(kitti))), 0);
  for (const char* name : {"poses.txt", "times.txt", "calib.txt"}) {
    fs::copy_file(testing::shared_file(std::string("data/kitti_raw_0005/") + name), kitti / name);
  }
  auto source = open_reader(kitti, {});
  ASSERT_EQ(source->info().format, "semantickitti");
  ASSERT_EQ(source->size(), 100u);

  write_scan_sequence(*source, dir / "drive", [] { SequenceWriteOptions o; o.format = ScanFormat::kKittiRaw; return o; }());
  const PcdEncoding pcd = pcd_compression_available() ? PcdEncoding::kBinaryCompressed : PcdEncoding::kBinary;
  write_scan_sequence(*source, dir / "pcd", [&] { SequenceWriteOptions o; o.format = ScanFormat::kPcd; o.pcd = pcd; return o; }());
  for (const fs::path& layout : {dir / "drive", dir / "pcd"}) {
    SCOPED_TRACE(layout.string());
    auto other = open_reader(layout, {});
    ASSERT_EQ(other->size(), source->size());
    for (std::size_t i = 0; i < source->size(); ++i) EXPECT_NEAR(other->info().times[i], source->info().times[i], 1e-6) << i;
    const auto reference = *source->info().camera_poses;  // Tr is the identity: LiDAR frame
    const auto poses = *other->info().camera_poses;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      ASSERT_LT((poses[i].matrix() - reference[i].matrix()).norm(), 1e-6) << i;
    }
    for (std::size_t i = 0; i < source->size(); i += 9) {
      const LabelledCloud a = source->scan(i), b = other->scan(i);
      ASSERT_EQ(a.size(), b.size()) << i;
      ASSERT_EQ(a.points, b.points) << i;
      ASSERT_EQ(a.remission, b.remission) << i;
    }
  }
  // What `saloam info` reports for the real drive: 64 beams, 10 Hz.
  auto drive = open_reader(dir / "drive", {});
  const SequenceSummary summary = summarize(*drive, 1);
  EXPECT_EQ(summary.format, "kitti-raw");
  EXPECT_NEAR(summary.median_interval, 0.1, 1e-6);
  ASSERT_TRUE(summary.beams.has_value());
  EXPECT_EQ(summary.beams->method, BeamMethod::kAzimuthWraps);
  EXPECT_NEAR(static_cast<double>(summary.beams->beams), 64.0, 1.0);
}

}  // namespace
}  // namespace saloam
