#include "saloam/segmentation/knn_labels.hpp"

#include <gtest/gtest.h>

namespace saloam {
namespace {

// A 3 x 8 image of one ring per row: a wall at 10 m (class 2) and, in
// columns 3-4 of the middle row, a pole at 5 m (class 5).
struct Scene {
  LabelledCloud cloud;
  std::vector<std::int16_t> rings;
  std::vector<std::int16_t> pixel_class;
  RangeImage image;
};

ProjectionSpec spec8() {
  ProjectionSpec spec;
  spec.columns = 8;
  spec.channels = {ImageChannel::kRange};
  spec.means = {0.0f};
  spec.stds = {1.0f};
  return spec;
}

Eigen::Vector3f at(double range, int column) {
  const double azimuth = M_PI * (1.0 - 2.0 * (column + 0.5) / 8.0);
  return Eigen::Vector3f(static_cast<float>(range * std::cos(azimuth)), static_cast<float>(range * std::sin(azimuth)), 0);
}

Scene scene() {
  Scene s;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 8; ++col) {
      const bool pole = row == 1 && (col == 3 || col == 4);
      s.cloud.push_back(at(pole ? 5.0 : 10.0, col), 0);
      s.rings.push_back(static_cast<std::int16_t>(row));
    }
  s.image = project_scan(s.cloud, s.rings, 3, spec8());
  s.pixel_class.assign(s.image.pixels(), 2);
  s.pixel_class[1 * 8 + 3] = s.pixel_class[1 * 8 + 4] = 5;
  return s;
}

TEST(KnnLabels, ShownPointsKeepTheirPixelsClassInUniformRegions) {
  Scene s = scene();
  const auto classes = point_classes(s.image, s.pixel_class, point_ranges(s.cloud), 8, KnnOptions{});
  for (std::size_t i = 0; i < s.cloud.size(); ++i) EXPECT_EQ(classes[i], s.pixel_class[s.image.point_pixel[i]]) << i;
}

TEST(KnnLabels, AHiddenPointBehindAPoleTakesTheClassOfItsRange) {
  Scene s = scene();
  // A wall point hidden behind the pole pixel (1, 3): its own pixel says
  // pole, but the k nearest ranges around it are wall pixels.
  s.cloud.push_back(at(10.0, 3), 0);
  s.rings.push_back(1);
  s.image = project_scan(s.cloud, s.rings, 3, spec8());
  const auto classes = point_classes(s.image, s.pixel_class, point_ranges(s.cloud), 8, KnnOptions{});
  EXPECT_EQ(s.image.point_pixel.back(), 1 * 8 + 3);
  EXPECT_EQ(classes.back(), 2);
  // A point 2.5 m from every pixel's range has no neighbour within the
  // cutoff (1 m): it keeps its pixel's class.
  s.cloud.push_back(at(7.5, 3), 0);
  s.rings.push_back(1);
  s.image = project_scan(s.cloud, s.rings, 3, spec8());
  const auto alone = point_classes(s.image, s.pixel_class, point_ranges(s.cloud), 8, KnnOptions{});
  EXPECT_EQ(alone.back(), 5);
}

TEST(KnnLabels, TheWindowWrapsAroundInAzimuth) {
  Scene s = scene();
  // Column 0's point, hidden behind a near object of class 5 in its pixel,
  // finds its wall neighbours across the seam in column 7.
  s.pixel_class.assign(s.image.pixels(), 5);
  for (int row = 0; row < 3; ++row) s.pixel_class[row * 8 + 7] = s.pixel_class[row * 8 + 6] = 2;
  s.cloud.points[1 * 8 + 0] = at(10.0, 0);
  for (int row = 0; row < 3; ++row)
    for (int col : {0, 1, 2}) s.cloud.points[row * 8 + col] = at(3.0, col);
  s.cloud.push_back(at(10.0, 0), 0);
  s.rings.push_back(1);
  s.image = project_scan(s.cloud, s.rings, 3, spec8());
  const auto classes = point_classes(s.image, s.pixel_class, point_ranges(s.cloud), 8, KnnOptions{});
  EXPECT_EQ(classes.back(), 2);
}

TEST(KnnLabels, ClassZeroNeverWinsAndPointsWithoutPixelGetIt) {
  Scene s = scene();
  s.pixel_class.assign(s.image.pixels(), 0);
  s.pixel_class[0] = 3;
  s.cloud.push_back({0, 0, 0}, 0);  // no pixel
  s.rings.push_back(0);
  s.image = project_scan(s.cloud, s.rings, 3, spec8());
  KnnOptions all;
  all.k = 25;  // every pixel of the window votes
  const auto classes = point_classes(s.image, s.pixel_class, point_ranges(s.cloud), 8, all);
  EXPECT_EQ(classes[1], 3);  // its neighbour (0, 0) is the only vote that counts
  EXPECT_EQ(classes.back(), 0);
}

}  // namespace
}  // namespace saloam
