#include "saloam/segmentation/range_projection.hpp"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

namespace saloam {
namespace {

ProjectionSpec raw_spec(int columns) {
  ProjectionSpec spec;
  spec.columns = columns;
  spec.means.assign(spec.channels.size(), 0.0f);
  spec.stds.assign(spec.channels.size(), 1.0f);
  return spec;
}

float channel(const RangeImage& image, int c, int row, int col) {
  return image.data[static_cast<std::size_t>(c) * image.pixels() + static_cast<std::size_t>(row * image.cols + col)];
}

TEST(RangeProjection, ColumnsFollowRangeNetsConvention) {
  // Behind (azimuth +-180 deg) is column 0, straight ahead the middle column,
  // and columns increase clockwise seen from above (behind, left, ahead, right).
  EXPECT_EQ(projection_column(-10.0f, 1e-6f, 2048), 0);
  EXPECT_EQ(projection_column(0.0f, 10.0f, 2048), 512);    // left (y > 0)
  EXPECT_EQ(projection_column(10.0f, 0.0f, 2048), 1024);
  EXPECT_EQ(projection_column(0.0f, -10.0f, 2048), 1536);  // right
  EXPECT_EQ(projection_column(-10.0f, -1e-6f, 2048), 2047);
}

TEST(RangeProjection, ColumnsAreThoseOfTheDoubleAtan2EvenAtColumnEdges) {
  // Points on and beside every column edge of a 2048- and a 1000-column
  // image, at ranges from 1 to 120 m: the column the double-precision
  // atan2 gives (the definition) is the column.
  constexpr double kPi = 3.14159265358979323846;
  int compared = 0;
  for (const int columns : {2048, 1000}) {
    for (int edge = 0; edge < columns; edge += 3) {
      for (const double offset : {-1e-6, -1e-7, 0.0, 1e-7, 1e-6, 0.3}) {
        const double azimuth = kPi * (1.0 - 2.0 * (edge + offset) / columns);
        for (const double range : {1.0, 17.3, 120.0}) {
          const auto x = static_cast<float>(range * std::cos(azimuth));
          const auto y = static_cast<float>(range * std::sin(azimuth));
          const double u = 0.5 * (1.0 - std::atan2(static_cast<double>(y), static_cast<double>(x)) / kPi);
          const int expected = std::clamp(static_cast<int>(std::floor(u * columns)), 0, columns - 1);
          ASSERT_EQ(projection_column(x, y, columns), expected) << "x " << x << " y " << y << " columns " << columns;
          ++compared;
        }
      }
    }
  }
  EXPECT_GT(compared, 10000);
}

TEST(RangeProjection, RingRowsAndTheClosestPointPerPixel) {
  LabelledCloud cloud;
  cloud.push_back({10.0f, 0.0f, 0.0f}, 0.5f);   // ring 0, ahead
  cloud.push_back({5.0f, 0.0f, 0.0f}, 0.25f);   // same pixel, closer: shown
  cloud.push_back({-8.0f, 0.0f, -1.0f}, 0.1f);  // ring 3, behind
  cloud.push_back({1.0f, 1.0f, 1.0f}, 0.1f);    // no ring: no pixel
  const std::vector<std::int16_t> rings{0, 0, 3, -1};
  const RangeImage image = project_scan(cloud, rings, 4, raw_spec(8));
  ASSERT_EQ(image.rows, 4);
  ASSERT_EQ(image.cols, 8);
  EXPECT_EQ(image.point_pixel[0], 4);
  EXPECT_EQ(image.point_pixel[1], 4);
  EXPECT_EQ(image.shown[4], 1);
  EXPECT_FLOAT_EQ(image.range[4], 5.0f);
  EXPECT_EQ(image.point_pixel[2], 3 * 8 + 0);  // azimuth atan2(+0, -8) = +pi: column 0
  EXPECT_EQ(image.point_pixel[3], -1);
  // Channels range, x, y, z, remission, mask of the shown point; empty pixels 0.
  EXPECT_FLOAT_EQ(channel(image, 0, 0, 4), 5.0f);
  EXPECT_FLOAT_EQ(channel(image, 1, 0, 4), 5.0f);
  EXPECT_FLOAT_EQ(channel(image, 4, 0, 4), 0.25f);
  EXPECT_FLOAT_EQ(channel(image, 5, 0, 4), 1.0f);
  for (int c = 0; c < 6; ++c) EXPECT_EQ(channel(image, c, 1, 1), 0.0f);
}

TEST(RangeProjection, ChannelsAreNormalisedAndEmptyPixelsStayZero) {
  LabelledCloud cloud;
  cloud.push_back({10.0f, 0.0f, 0.0f}, 0.5f);
  ProjectionSpec spec = raw_spec(4);
  spec.channels = {ImageChannel::kRange, ImageChannel::kRemission};
  spec.means = {12.0f, 0.25f};
  spec.stds = {2.0f, 0.5f};
  const RangeImage image = project_scan(cloud, std::vector<std::int16_t>{0}, 1, spec);
  EXPECT_FLOAT_EQ(channel(image, 0, 0, 2), -1.0f);
  EXPECT_FLOAT_EQ(channel(image, 1, 0, 2), 0.5f);
  EXPECT_EQ(channel(image, 0, 0, 0), 0.0f);
}

TEST(RangeProjection, ElevationRowsAreUniformBetweenTheFieldOfViewEdges) {
  ProjectionSpec spec = raw_spec(16);
  spec.row_mode = RowMode::kElevation;
  spec.rows = 28;
  spec.fov_up_deg = 3.0;
  spec.fov_down_deg = -25.0;
  LabelledCloud cloud;
  auto at_elevation = [](double deg) {
    const double e = deg * M_PI / 180.0;
    return Eigen::Vector3f(static_cast<float>(10 * std::cos(e)), 0.0f, static_cast<float>(10 * std::sin(e)));
  };
  cloud.push_back(at_elevation(2.5), 0);    // row 0 (1 deg per row)
  cloud.push_back(at_elevation(-0.5), 0);   // row 3
  cloud.push_back(at_elevation(-24.5), 0);  // row 27
  cloud.push_back(at_elevation(10.0), 0);   // above the field of view: clamped to row 0
  cloud.push_back(at_elevation(-40.0), 0);  // below: the last row
  const RangeImage image = project_scan(cloud, {}, 0, spec);
  ASSERT_EQ(image.rows, 28);
  EXPECT_EQ(image.point_pixel[0] / 16, 0);
  EXPECT_EQ(image.point_pixel[1] / 16, 3);
  EXPECT_EQ(image.point_pixel[2] / 16, 27);
  EXPECT_EQ(image.point_pixel[3] / 16, 0);
  EXPECT_EQ(image.point_pixel[4] / 16, 27);
}

TEST(RangeProjection, PointsThatAreNotFiniteOrAtTheOriginGetNoPixel) {
  LabelledCloud cloud;
  cloud.push_back({std::nanf(""), 0.0f, 0.0f}, 0);
  cloud.push_back({0.0f, 0.0f, 0.0f}, 0);
  cloud.push_back({INFINITY, 0.0f, 0.0f}, 0);
  const RangeImage image = project_scan(cloud, std::vector<std::int16_t>{0, 0, 0}, 1, raw_spec(8));
  for (const auto p : image.point_pixel) EXPECT_EQ(p, -1);
  for (const auto s : image.shown) EXPECT_EQ(s, -1);
}

}  // namespace
}  // namespace saloam
