// The semantic local map: exact radius-bounded k-NN of the neighbour grid
// (against brute force) and the sliding window of N_m frames with the
// newest point per voxel, classes apart; semantic voxel downsampling.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/odometry/local_map.hpp"

namespace saloam {
namespace {

struct Labelled {
  Eigen::Vector3d p;
  ClassIndex c;
};

// The k nearest points of class c within `radius` of q, by exhaustive search.
std::vector<double> brute_force_squared_distances(const std::vector<Labelled>& points, const Eigen::Vector3d& q,
                                                  ClassIndex c, int k, double radius) {
  std::vector<double> d2;
  for (const auto& [p, pc] : points) {
    const double d = (p - q).squaredNorm();
    if (pc == c && d <= radius * radius) d2.push_back(d);
  }
  std::sort(d2.begin(), d2.end());
  if (static_cast<int>(d2.size()) > k) d2.resize(static_cast<std::size_t>(k));
  return d2;
}

TEST(NeighbourGrid, NearestEqualsBruteForce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-6.0, 6.0);
  std::uniform_int_distribution<int> cls(0, 2);
  NeighbourGrid grid(1.0);
  std::vector<Labelled> points;
  // Clustered points (a surface and a pole) plus uniform clutter, across
  // negative and positive cell coordinates.
  for (int i = 0; i < 3000; ++i) {
    const Labelled l{{u(rng), u(rng), 0.05 * u(rng)}, static_cast<ClassIndex>(cls(rng))};
    points.push_back(l);
  }
  for (int i = 0; i < 200; ++i) points.push_back({{1.5, -2.5, 0.03 * i}, 3});
  for (const auto& [p, c] : points) grid.insert(p, c);
  EXPECT_EQ(grid.size(), points.size());
  EXPECT_EQ(grid.size(3), 200u);

  std::array<Eigen::Vector3d, 8> found{};
  std::array<double, 8> d2{};
  int full = 0;
  for (int q = 0; q < 2000; ++q) {
    const Eigen::Vector3d query(u(rng), u(rng), 0.3 * u(rng));
    const auto c = static_cast<ClassIndex>(q % 4);
    const int k = 1 + q % 8;
    const double radius = q % 3 == 0 ? 0.4 : 1.0;
    const int n = grid.nearest(query, c, k, radius, found.data(), d2.data());
    const auto expected = brute_force_squared_distances(points, query, c, k, radius);
    ASSERT_EQ(n, static_cast<int>(expected.size())) << "query " << q;
    full += n == k;
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR(d2[i], expected[i], 1e-12) << "query " << q << " neighbour " << i;
      EXPECT_NEAR((found[i] - query).squaredNorm(), d2[i], 1e-12);
    }
  }
  EXPECT_GT(full, 500);  // the test exercises full neighbour sets, not only sparse ones
}

TEST(NeighbourGrid, RadiusBeyondTheMaximumIsClamped) {
  NeighbourGrid grid(0.5);
  grid.insert({0.0, 0.0, 0.0}, 0);
  grid.insert({0.9, 0.0, 0.0}, 0);  // 0.8 m from the query: beyond the grid's 0.5 m
  Eigen::Vector3d p[2];
  double d2[2];
  EXPECT_EQ(grid.nearest({0.1, 0.0, 0.0}, 0, 2, 5.0, p, d2), 1);
  EXPECT_NEAR(d2[0], 0.01, 1e-12);
}

TEST(NeighbourGrid, EraseRemovesExactlyOnePoint) {
  NeighbourGrid grid(1.0);
  const Eigen::Vector3d a(0.2, 0.3, 0.4), b(0.25, 0.3, 0.4);
  grid.insert(a, 1);
  grid.insert(a, 1);
  grid.insert(b, 1);
  EXPECT_FALSE(grid.erase(a, 2));  // other class
  EXPECT_FALSE(grid.erase({5.0, 5.0, 5.0}, 1));
  EXPECT_TRUE(grid.erase(a, 1));
  EXPECT_EQ(grid.size(), 2u);
  EXPECT_TRUE(grid.erase(a, 1));
  EXPECT_FALSE(grid.erase(a, 1));
  Eigen::Vector3d p[3];
  double d2[3];
  ASSERT_EQ(grid.nearest(a, 1, 3, 1.0, p, d2), 1);
  EXPECT_EQ(p[0], b);
  EXPECT_TRUE(grid.erase(b, 1));
  EXPECT_EQ(grid.size(), 0u);
  EXPECT_EQ(grid.nearest(a, 1, 3, 1.0, p, d2), 0);
}

TEST(NeighbourGrid, RejectsNonPositiveCellSize) { EXPECT_THROW(NeighbourGrid(0.0), std::invalid_argument); }

FeatureCloud cloud_of(std::initializer_list<Eigen::Vector3d> points, ClassIndex c) {
  FeatureCloud cloud;
  for (const auto& p : points) cloud.push_back(p, c, 0.0f);
  return cloud;
}

TEST(SemanticLocalMap, NewestPolicyKeepsTheNewestPointPerVoxelOverTheLastFrames) {
  ClassVoxelSizes sizes{};
  sizes.fill(0.5);
  SemanticLocalMap map(2, sizes, 1.0, MapVoxelPoint::kNewest);
  EXPECT_TRUE(map.empty());
  const Eigen::Vector3d first(0.1, 0.1, 0.1), second(0.2, 0.2, 0.2), far(3.1, 0.1, 0.1);
  map.add_frame(cloud_of({first, far}, 0), FeatureCloud{});
  map.add_frame(cloud_of({second}, 0), FeatureCloud{});  // same voxel as `first`: replaces it
  EXPECT_EQ(map.num_edge_points(), 2u);
  Eigen::Vector3d p[2];
  double d2[2];
  ASSERT_EQ(map.edges().nearest(first, 0, 2, 1.0, p, d2), 1);
  EXPECT_EQ(p[0], second);
  // A third frame pushes the first out of the window: `far` goes, the voxel
  // taken over by the second frame stays.
  map.add_frame(FeatureCloud{}, cloud_of({far}, 4));
  EXPECT_EQ(map.num_edge_points(), 1u);
  EXPECT_EQ(map.edges().nearest(far, 0, 1, 1.0, p, d2), 0);
  EXPECT_EQ(map.edges().nearest(first, 0, 1, 1.0, p, d2), 1);
  EXPECT_EQ(map.num_planar_points(), 1u);
  EXPECT_EQ(map.planars().size(4), 1u);
  // Two more frames and the second frame's voxel is gone too.
  map.add_frame(FeatureCloud{}, FeatureCloud{});
  map.add_frame(FeatureCloud{}, FeatureCloud{});
  EXPECT_EQ(map.num_edge_points(), 0u);
  EXPECT_EQ(map.num_planar_points(), 0u);
}

TEST(SemanticLocalMap, FirstPolicyKeepsTheFirstPointWhileTheVoxelIsObserved) {
  ClassVoxelSizes sizes{};
  sizes.fill(0.5);
  SemanticLocalMap map(2, sizes, 1.0, MapVoxelPoint::kFirst);
  const Eigen::Vector3d first(0.1, 0.1, 0.1), second(0.2, 0.2, 0.2), far(3.1, 0.1, 0.1);
  map.add_frame(cloud_of({first, far}, 0), FeatureCloud{});
  Eigen::Vector3d p[2];
  double d2[2];
  // The voxel of `first` is observed by every later frame: it keeps `first`
  // however long the sequence, while `far`, seen once, leaves after N_m = 2.
  for (int frame = 1; frame < 6; ++frame) {
    map.add_frame(cloud_of({second}, 0), FeatureCloud{});
    ASSERT_EQ(map.edges().nearest(second, 0, 2, 1.0, p, d2), 1) << "frame " << frame;
    EXPECT_EQ(p[0], first);
    EXPECT_EQ(map.edges().nearest(far, 0, 1, 1.0, p, d2), frame < 2 ? 1 : 0) << "frame " << frame;
  }
  EXPECT_EQ(map.num_edge_points(), 1u);
  map.add_frame(FeatureCloud{}, FeatureCloud{});
  EXPECT_EQ(map.num_edge_points(), 1u);  // observed by the previous frame: still in the window
  map.add_frame(FeatureCloud{}, FeatureCloud{});
  EXPECT_EQ(map.num_edge_points(), 0u);
}

TEST(SemanticLocalMap, PolicyFromTheConfig) {
  OdometryConfig config;
  EXPECT_EQ(map_voxel_point(config), MapVoxelPoint::kFirst);
  config.local_map_point = "newest";
  EXPECT_EQ(map_voxel_point(config), MapVoxelPoint::kNewest);
}

TEST(SemanticLocalMap, ClassesNeverShareAVoxel) {
  ClassVoxelSizes sizes{};
  sizes.fill(0.4);
  SemanticLocalMap map(20, sizes, 1.0);
  FeatureCloud planars = cloud_of({{1.0, 1.0, 0.0}}, 1);
  planars.push_back({1.01, 1.0, 0.0}, 9, 0.0f);  // same voxel, other class
  planars.push_back({1.02, 1.0, 0.0}, 1, 0.0f);  // same voxel and class: dropped
  map.add_frame(FeatureCloud{}, planars);
  EXPECT_EQ(map.num_planar_points(), 2u);
  EXPECT_EQ(map.planars().size(1), 1u);
  EXPECT_EQ(map.planars().size(9), 1u);
}

TEST(VoxelDownsample, ClassesKeepTheirOwnVoxels) {
  FeatureCloud cloud;
  for (int i = 0; i < 100; ++i) {
    cloud.push_back(Eigen::Vector3d(0.01 * i, 0, 0), 1, 0.0f);  // 1 m of class 1
    cloud.push_back(Eigen::Vector3d(0.01 * i, 0, 0), 2, 0.0f);  // same points, class 2
  }
  ClassVoxelSizes sizes{};
  sizes.fill(1.0);
  sizes[2] = 0.1;
  const auto down = voxel_downsample(cloud, sizes);
  int n1 = 0, n2 = 0;
  for (auto c : down.classes) (c == 1 ? n1 : n2)++;
  EXPECT_EQ(n1, 1);
  EXPECT_EQ(n2, 10);
}

TEST(VoxelDownsample, SemanticSizesFineForSmallObjects) {
  OdometryConfig config;
  const auto sizes = class_voxel_sizes(config);
  EXPECT_LT(sizes[to_learning_class(cls::kPole)], sizes[to_learning_class(cls::kRoad)]);
  EXPECT_LT(sizes[to_learning_class(cls::kTrafficSign)], sizes[to_learning_class(cls::kBuilding)]);
  config.use_semantics = false;
  const auto plain = class_voxel_sizes(config);
  for (double s : plain) EXPECT_EQ(s, config.voxel_size);
}

}  // namespace
}  // namespace saloam
