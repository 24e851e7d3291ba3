// FrameSource's promises as the frame range stage keeps them, over a
// rereadable source and over a stream; SequenceFolderSource's info.

#include <gtest/gtest.h>

#include <stdexcept>

#include "saloam/core/error.hpp"
#include "saloam/io/frame_source.hpp"
#include "saloam/io/sequence_source.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

/// n frames; frame i is one point at x = i; poses move 1 m per frame. As a
/// stream it throws unless asked for frames 0, 1, 2, ... in order.
class CountingSource final : public FrameSource {
 public:
  CountingSource(std::size_t n, bool rereadable) {
    info_.name = "counting";
    info_.rereadable = rereadable;
    info_.velo_to_cam = Pose::Identity();
    info_.camera_poses.emplace();
    for (std::size_t i = 0; i < n; ++i) {
      info_.times.push_back(0.1 * static_cast<double>(i));
      Pose p = Pose::Identity();
      p.translation().x() = static_cast<double>(i);
      info_.camera_poses->push_back(p);
    }
  }
  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  LabelledCloud scan(std::size_t i) override {
    if (!info_.rereadable && i != next_) throw std::logic_error("out of order");
    next_ = i + 1;
    asked.push_back(i);
    LabelledCloud cloud;
    cloud.push_back({static_cast<float>(i), 0.0f, 0.0f}, 0.5f);
    return cloud;
  }
  std::vector<std::size_t> asked;

 private:
  SourceInfo info_;
  std::size_t next_ = 0;
};

TEST(FrameRangeSource, ServesTheRangeFromZeroWithItsTimesPosesAndFirstFrame) {
  auto inner = std::make_unique<CountingSource>(10, true);
  FrameRangeSource range(std::move(inner), FrameRange::parse("3:7"));
  ASSERT_EQ(range.size(), 4u);
  EXPECT_EQ(range.info().first_frame, 3u);
  EXPECT_DOUBLE_EQ(range.info().times.front(), 0.3);
  ASSERT_TRUE(range.info().camera_poses);
  ASSERT_EQ(range.info().camera_poses->size(), 4u);
  EXPECT_DOUBLE_EQ(range.info().camera_poses->back().translation().x(), 6.0);
  EXPECT_FALSE(range.info().sensor_camera_poses);
  EXPECT_FLOAT_EQ(range.scan(2).points[0].x(), 5.0f);
  EXPECT_FLOAT_EQ(range.scan(0).points[0].x(), 3.0f);  // rereadable: any order
  EXPECT_THROW((void)range.scan(4), std::out_of_range);
}

TEST(FrameRangeSource, OverAStreamReadsAndDropsTheFramesBeforeTheRange) {
  auto inner = std::make_unique<CountingSource>(10, false);
  const CountingSource& counting = *inner;
  FrameRangeSource range(std::move(inner), FrameRange::parse("4:"));
  EXPECT_FALSE(range.info().rereadable);
  ASSERT_EQ(range.size(), 6u);
  EXPECT_FLOAT_EQ(range.scan(0).points[0].x(), 4.0f);
  EXPECT_FLOAT_EQ(range.scan(1).points[0].x(), 5.0f);
  EXPECT_EQ(counting.asked, (std::vector<std::size_t>{0, 1, 2, 3, 4, 5}));
}

TEST(FrameRangeSource, RangesOfRangesAddTheirOffsets) {
  auto inner = std::make_unique<FrameRangeSource>(std::make_unique<CountingSource>(10, true), FrameRange::parse("2:"));
  FrameRangeSource range(std::move(inner), FrameRange::parse("1:3"));
  EXPECT_EQ(range.info().first_frame, 3u);
  EXPECT_FLOAT_EQ(range.scan(1).points[0].x(), 4.0f);
}

TEST(FrameRangeSource, ARangeOutsideTheFramesIsAConfigError) {
  EXPECT_THROW(FrameRangeSource(std::make_unique<CountingSource>(5, true), FrameRange::parse("5:9")), ConfigError);
}

TEST(SequenceFolderSource, HoldsTheFoldersTimesPosesCalibrationAndLabels) {
  testing::TempDir dir;
  SequenceWriter w(dir.path());
  LabelledCloud cloud;
  cloud.has_labels = true;
  for (int i = 0; i < 4; ++i) cloud.push_back({1.0f + static_cast<float>(i), 2.0f, -1.7f}, 0.3f, 40, 0);
  for (std::size_t i = 0; i < 2; ++i) w.write_scan(i, cloud);
  w.write_camera_poses({Pose::Identity(), Pose::Identity()});
  w.write_calib(Pose::Identity());
  w.write_times({0.0, 0.1});

  SequenceFolderSource source{SequenceReader(dir.path())};
  EXPECT_EQ(source.size(), 2u);
  EXPECT_TRUE(source.info().has_labels);
  EXPECT_TRUE(source.info().rereadable);
  EXPECT_TRUE(source.info().velo_to_cam);
  ASSERT_TRUE(source.info().camera_poses);
  EXPECT_EQ(source.info().camera_poses->size(), 2u);
  EXPECT_FALSE(source.info().sensor_camera_poses);
  EXPECT_EQ(source.info().folder, dir.path());
  EXPECT_EQ(source.scan(1).size(), 4u);

  const SequenceFolderSource without_calib(SequenceReader(dir.path()), false);
  EXPECT_FALSE(without_calib.info().velo_to_cam);
  SequenceOptions no_labels;
  no_labels.ignore_labels = true;
  SequenceFolderSource unlabelled{SequenceReader(dir.path(), no_labels)};
  EXPECT_FALSE(unlabelled.info().has_labels);
  EXPECT_FALSE(unlabelled.scan(0).has_labels);
}

}  // namespace
}  // namespace saloam
