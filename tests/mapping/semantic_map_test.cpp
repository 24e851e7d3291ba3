#include <gtest/gtest.h>

#include "saloam/core/lie.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/mapping/map_render.hpp"
#include "saloam/mapping/semantic_map.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

/// A 10 x 10 m floor (road) with a 2 m wall (building) at x = 5, as seen from the origin.
LabelledCloud scene() {
  LabelledCloud c;
  c.has_labels = true;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) {
      c.push_back({-5.0f + 0.1f * i, -5.0f + 0.1f * j, -1.7f}, 0.2f, cls::kRoad, 0);
    }
  }
  for (int j = 0; j < 100; ++j) {
    for (int k = 0; k < 20; ++k) c.push_back({5.0f, -5.0f + 0.1f * j, -1.7f + 0.1f * k}, 0.5f, cls::kBuilding, 0);
  }
  c.push_back({1.0f, 1.0f, -1.0f}, 0.1f, cls::kMovingCar, 3);
  return c;
}

TEST(SemanticMap, SamePlaceTwiceFillsTheSameVoxels) {
  SemanticMap map({0.5, 60.0, true, false});
  const auto s = scene();
  map.insert(s, Pose::Identity());
  const std::size_t once = map.num_voxels();
  // The same world seen from a pose 1 m further: points given in that sensor frame.
  Pose shift = Pose::Identity();
  shift.translation() = Eigen::Vector3d(1.0, 0.0, 0.0);
  LabelledCloud moved = s;
  for (auto& p : moved.points) p = (shift.inverse().cast<float>() * p);
  map.insert(moved, shift);
  EXPECT_EQ(map.num_voxels(), once);
  const auto cloud = map.to_cloud();
  EXPECT_EQ(cloud.size(), once);
  EXPECT_TRUE(cloud.has_labels);
  std::size_t road = 0, building = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_FALSE(is_dynamic(cloud.label[i]));  // the moving car is left out
    road += cloud.label[i] == cls::kRoad;
    building += cloud.label[i] == cls::kBuilding;
    if (cloud.label[i] == cls::kBuilding) {
      EXPECT_NEAR(cloud.points[i].x(), 5.0f, 1e-4);
    }
  }
  EXPECT_EQ(road, 20u * 20u);  // 10 m / 0.5 m squared
  EXPECT_GT(building, 0u);
}

TEST(SemanticMap, MajorityVoteAndRangeLimit) {
  SemanticMap map({1.0, 10.0, true, false});
  LabelledCloud c;
  c.has_labels = true;
  for (int i = 0; i < 3; ++i) c.push_back({0.5f, 0.5f, 0.5f}, 0.0f, cls::kVegetation, 0);
  c.push_back({0.4f, 0.4f, 0.4f}, 0.0f, cls::kTrunk, 0);
  c.push_back({50.0f, 0.0f, 0.0f}, 0.0f, cls::kBuilding, 0);  // beyond max_range
  map.insert(c, Pose::Identity());
  const auto cloud = map.to_cloud();
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_EQ(cloud.label[0], cls::kVegetation);
  EXPECT_NEAR(cloud.points[0].x(), 0.475f, 1e-5);
}

TEST(MapRender, WritesAPicture) {
  testing::TempDir dir;
  SemanticMap map(SemanticMapOptions::from_config(SlamConfig{}));
  map.insert(scene(), Pose::Identity());
  std::vector<Pose> trajectory(3, Pose::Identity());
  trajectory[1].translation().x() = 1.0;
  trajectory[2].translation().x() = 2.0;
  render_top_down(dir / "map.png", map.to_cloud(), trajectory, {0.1, 2000, true});
  EXPECT_GT(std::filesystem::file_size(dir / "map.png"), 500u);
}

TEST(MapRender, HighestPointWinsAndSizeFollowsTheOptions) {
  TopDownCanvas canvas({-6, -6}, {6, 6}, {0.1, 2000, true});
  EXPECT_EQ(canvas.stats().width, 120);
  EXPECT_EQ(canvas.stats().height, 120);
  LabelledCloud s = scene();
  canvas.add(s);
  // The wall (x = 5) stands over the road; elsewhere the road shows.
  EXPECT_EQ(canvas.shown_label(5.0, 0.0), cls::kBuilding);
  EXPECT_EQ(canvas.shown_label(-2.0, 3.0), cls::kRoad);
  EXPECT_EQ(canvas.shown_label(1.0, 1.0), cls::kMovingCar);  // above the road there
  EXPECT_EQ(canvas.shown_label(-5.9, -5.9), 0);             // nothing drawn
  EXPECT_EQ(canvas.shown_label(40.0, 0.0), 0);              // outside
  canvas.add(Eigen::Vector3d(100, 100, 0), cls::kRoad);     // outside: not drawn
  EXPECT_EQ(canvas.stats().points_drawn, s.size());
  // North up: a point at larger y lands on a smaller row, so the picture is
  // not mirrored (checked through the class lookup on both sides).
  canvas.add(Eigen::Vector3d(-3, 4, 1.0), cls::kPole);
  EXPECT_EQ(canvas.shown_label(-3, 4), cls::kPole);
  EXPECT_EQ(canvas.shown_label(-3, -4), cls::kRoad);
  testing::TempDir dir;
  const TopDownStats written = canvas.save(dir / "map.png", {Pose::Identity()});
  EXPECT_EQ(written.width, 120);
  EXPECT_GT(std::filesystem::file_size(dir / "map.png"), 500u);
}

TEST(MapRender, ResolutionIsWidenedToRespectTheLargestSide) {
  const TopDownCanvas canvas({0, 0}, {1000, 500}, {0.1, 800, true});
  EXPECT_EQ(canvas.stats().width, 800);
  EXPECT_EQ(canvas.stats().height, 400);
  EXPECT_NEAR(canvas.stats().metres_per_pixel, 1.25, 1e-9);
  const TopDownCanvas fitted({0, 0}, {100, 50}, {0.0, 500, true});
  EXPECT_EQ(fitted.stats().width, 500);
  EXPECT_NEAR(fitted.stats().metres_per_pixel, 0.2, 1e-9);
}

}  // namespace
}  // namespace saloam
