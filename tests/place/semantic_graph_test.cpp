// Semantic graph construction on synthetic labelled clouds, and JSON I/O.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <set>

#include "saloam/core/error.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/place/graph_json.hpp"
#include "saloam/place/semantic_graph.hpp"
#include "saloam/place/sgpr_network.hpp"
#include "saloam/sim/simulator.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

/// Adds `count` points uniformly in a box centred at `centre` with half sizes `half`.
void add_blob(LabelledCloud& cloud, std::mt19937& rng, const Eigen::Vector3f& centre, const Eigen::Vector3f& half,
              int count, std::uint16_t label, std::uint16_t instance = 0) {
  std::uniform_real_distribution<float> u(-1.0F, 1.0F);
  for (int i = 0; i < count; ++i)
    cloud.push_back(centre + Eigen::Vector3f(u(rng), u(rng), u(rng)).cwiseProduct(half), 0.5F, label, instance);
  cloud.has_labels = true;
}

/// Reference clustering: O(n^2) union-find over all pairs within tolerance.
std::vector<std::set<std::uint32_t>> brute_force_clusters(const std::vector<Eigen::Vector3f>& points, double tolerance,
                                                          std::size_t min_size) {
  const std::size_t n = points.size();
  std::vector<std::size_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if ((points[i] - points[j]).squaredNorm() <= static_cast<float>(tolerance * tolerance)) parent[find(i)] = find(j);
  std::map<std::size_t, std::set<std::uint32_t>> groups;
  for (std::size_t i = 0; i < n; ++i) groups[find(i)].insert(static_cast<std::uint32_t>(i));
  std::vector<std::set<std::uint32_t>> out;
  for (auto& [root, members] : groups)
    if (members.size() >= min_size) out.push_back(members);
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::set<std::uint32_t>> as_sets(const std::vector<std::vector<std::uint32_t>>& clusters) {
  std::vector<std::set<std::uint32_t>> out;
  for (const auto& c : clusters) out.emplace_back(c.begin(), c.end());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(SemanticGraph, NodeClassMapping) {
  EXPECT_EQ(node_class_of(cls::kCar), node_class::kCar);
  EXPECT_EQ(node_class_of(cls::kMovingCar), node_class::kCar);
  EXPECT_EQ(node_class_of(cls::kTruck), node_class::kTruck);
  EXPECT_EQ(node_class_of(cls::kMovingTruck), node_class::kTruck);
  EXPECT_EQ(node_class_of(cls::kBus), node_class::kOtherVehicle);
  EXPECT_EQ(node_class_of(cls::kOtherVehicle), node_class::kOtherVehicle);
  EXPECT_EQ(node_class_of(cls::kSidewalk), node_class::kSidewalk);
  EXPECT_EQ(node_class_of(cls::kOtherGround), node_class::kOtherGround);
  EXPECT_EQ(node_class_of(cls::kBuilding), node_class::kBuilding);
  EXPECT_EQ(node_class_of(cls::kFence), node_class::kFence);
  EXPECT_EQ(node_class_of(cls::kVegetation), node_class::kVegetation);
  EXPECT_EQ(node_class_of(cls::kTrunk), node_class::kTrunk);
  EXPECT_EQ(node_class_of(cls::kTerrain), node_class::kTerrain);
  EXPECT_EQ(node_class_of(cls::kPole), node_class::kPole);
  EXPECT_EQ(node_class_of(cls::kTrafficSign), node_class::kTrafficSign);
  for (const auto none : {cls::kUnlabeled, cls::kOutlier, cls::kRoad, cls::kParking, cls::kLaneMarking, cls::kPerson,
                          cls::kMovingPerson, cls::kBicycle, cls::kMotorcycle, cls::kBicyclist, cls::kMotorcyclist,
                          cls::kOtherStructure, cls::kOtherObject})
    EXPECT_FALSE(node_class_of(none).has_value()) << class_name(none);
  EXPECT_EQ(node_class_name(node_class::kTrafficSign), "traffic-sign");
}

TEST(EuclideanClusters, MatchesBruteForceOnRandomClouds) {
  std::mt19937 rng(7);
  for (const double tolerance : {0.2, 0.5, 2.0}) {
    std::uniform_real_distribution<float> u(0.0F, 30.0F * static_cast<float>(tolerance));
    std::vector<Eigen::Vector3f> points(1500);
    for (auto& p : points) p = {u(rng), u(rng), u(rng) * 0.3F};
    std::vector<std::uint32_t> all(points.size());
    std::iota(all.begin(), all.end(), 0U);
    const auto ours = euclidean_clusters(points, all, tolerance, 3, 1000000);
    EXPECT_EQ(as_sets(ours), brute_force_clusters(points, tolerance, 3)) << "tolerance " << tolerance;
    EXPECT_GT(ours.size(), 10U);
  }
}

TEST(EuclideanClusters, ToleranceIsRespectedAlongChains) {
  // Points on a line: spacing just under the tolerance chains into one cluster,
  // just over it gives single points.
  for (const double tolerance : {0.2, 0.5, 2.0}) {
    std::vector<Eigen::Vector3f> near, far;
    for (int i = 0; i < 40; ++i) {
      near.emplace_back(static_cast<float>(0.95 * tolerance * i), 1.0F, 0.0F);
      far.emplace_back(static_cast<float>(1.05 * tolerance * i), 1.0F, 0.0F);
    }
    std::vector<std::uint32_t> all(40);
    std::iota(all.begin(), all.end(), 0U);
    EXPECT_EQ(euclidean_clusters(near, all, tolerance, 1, 1000).size(), 1U) << tolerance;
    EXPECT_EQ(euclidean_clusters(far, all, tolerance, 1, 1000).size(), 40U) << tolerance;
    // Size limits: clusters below min or above max are dropped.
    EXPECT_TRUE(euclidean_clusters(near, all, tolerance, 41, 1000).empty());
    EXPECT_TRUE(euclidean_clusters(near, all, tolerance, 1, 39).empty());
    EXPECT_TRUE(euclidean_clusters(far, all, tolerance, 2, 1000).empty());
  }
}

TEST(EuclideanClusters, UsesOnlyTheGivenIndicesAndKeepsInputOrder) {
  std::vector<Eigen::Vector3f> points{{0, 0, 0}, {100, 0, 0}, {0.1F, 0, 0}, {0.2F, 0, 0}, {100.1F, 0, 0}};
  const std::vector<std::uint32_t> subset{4, 3, 2, 0};  // point 1 left out
  const auto clusters = euclidean_clusters(points, subset, 0.5, 1, 100);
  ASSERT_EQ(clusters.size(), 2U);
  EXPECT_EQ(clusters[0], (std::vector<std::uint32_t>{4}));
  EXPECT_EQ(clusters[1], (std::vector<std::uint32_t>{3, 2, 0}));
}

TEST(SemanticGraph, BuildsNodesWithClassesAndCentroids) {
  std::mt19937 rng(1);
  LabelledCloud cloud;
  add_blob(cloud, rng, {10, 0, 0}, {2, 1, 0.7F}, 400, cls::kCar, 5);         // car instance
  add_blob(cloud, rng, {10, 4, 0}, {2, 1, 0.7F}, 400, cls::kMovingCar, 6);   // another car instance
  add_blob(cloud, rng, {-5, 8, 2}, {0.05F, 0.05F, 2}, 150, cls::kPole);       // two poles 3 m apart
  add_blob(cloud, rng, {-5, 11, 2}, {0.05F, 0.05F, 2}, 150, cls::kPole);
  add_blob(cloud, rng, {0, -15, 5}, {10, 0.3F, 5}, 2000, cls::kBuilding);
  add_blob(cloud, rng, {0, 0, -1.7F}, {20, 3, 0.02F}, 3000, cls::kRoad);      // no node
  add_blob(cloud, rng, {3, 3, 0}, {0.3F, 0.3F, 0.8F}, 300, cls::kPerson);     // discarded
  add_blob(cloud, rng, {30, 30, 0}, {0.05F, 0.05F, 0.5F}, 40, cls::kTrafficSign);  // below min size 50
  const SemanticGraph graph = build_semantic_graph(cloud);
  ASSERT_EQ(graph.size(), 5U);
  EXPECT_EQ(graph.nodes, (std::vector<int>{node_class::kCar, node_class::kCar, node_class::kBuilding, node_class::kPole,
                                           node_class::kPole}));
  EXPECT_LT((graph.centers[0] - Eigen::Vector3d(10, 0, 0)).norm(), 0.2);
  EXPECT_LT((graph.centers[1] - Eigen::Vector3d(10, 4, 0)).norm(), 0.2);
  EXPECT_LT((graph.centers[2] - Eigen::Vector3d(0, -15, 5)).norm(), 0.5);
  EXPECT_LT((graph.centers[3] - Eigen::Vector3d(-5, 8, 2)).norm(), 0.2);
  EXPECT_LT((graph.centers[4] - Eigen::Vector3d(-5, 11, 2)).norm(), 0.2);
  EXPECT_FALSE(graph.pose.has_value());
}

TEST(SemanticGraph, InstancesSplitTouchingCarsAndNeedMoreThan20Points) {
  std::mt19937 rng(2);
  LabelledCloud cloud;
  add_blob(cloud, rng, {10, 0, 0}, {2, 1, 0.7F}, 300, cls::kCar, 1);
  add_blob(cloud, rng, {10, 2.1F, 0}, {2, 1, 0.7F}, 300, cls::kCar, 2);  // touching the first
  add_blob(cloud, rng, {-10, 0, 0}, {0.3F, 0.3F, 0.3F}, 21, cls::kCar, 3);  // exactly 21 points: kept
  add_blob(cloud, rng, {-20, 0, 0}, {0.3F, 0.3F, 0.3F}, 20, cls::kCar, 4);  // 20 points: dropped
  GraphBuilderConfig config;
  EXPECT_EQ(build_semantic_graph(cloud, config).size(), 3U);
  // Without instance ids the two touching cars are one Euclidean cluster, and the
  // small ones fall below the minimum cluster size (100).
  config.use_instances = false;
  const auto geometric = build_semantic_graph(cloud, config);
  ASSERT_EQ(geometric.size(), 1U);
  EXPECT_NEAR(geometric.centers[0].y(), 1.05, 0.2);
}

TEST(SemanticGraph, StuffClassesIgnoreInstanceIds) {
  // A vegetation blob whose points carry stray instance ids (as label noise can
  // leave them) is still one Euclidean cluster.
  std::mt19937 rng(3);
  LabelledCloud cloud;
  add_blob(cloud, rng, {5, 5, 1}, {1, 1, 1}, 250, cls::kVegetation, 9);
  const auto graph = build_semantic_graph(cloud);
  ASSERT_EQ(graph.size(), 1U);
  EXPECT_EQ(graph.nodes[0], node_class::kVegetation);
}

TEST(SemanticGraph, MoreThan100ClustersKeepsTheLargestDeterministically) {
  std::mt19937 rng(4);
  LabelledCloud cloud;
  // 130 separate pole clusters of 100 + 2k points (all distinct sizes).
  std::vector<int> sizes(130);
  std::iota(sizes.begin(), sizes.end(), 0);
  std::shuffle(sizes.begin(), sizes.end(), rng);
  for (std::size_t k = 0; k < sizes.size(); ++k)
    add_blob(cloud, rng, {static_cast<float>(k % 13) * 3.0F, static_cast<float>(k / 13) * 3.0F, 0},
             {0.05F, 0.05F, 1.0F}, 100 + 2 * sizes[k], cls::kPole);
  const auto graph = build_semantic_graph(cloud);
  ASSERT_EQ(graph.size(), 100U);
  // The 30 smallest (sizes 0..29) are the ones left out.
  std::set<std::pair<long, long>> kept;
  for (const auto& c : graph.centers) kept.insert({std::lround(c.x() / 3.0), std::lround(c.y() / 3.0)});
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    const bool present = kept.count({static_cast<long>(k % 13), static_cast<long>(k / 13)}) > 0;
    EXPECT_EQ(present, sizes[k] >= 30) << k;
  }
  // Same result on a second run and with the points in another order.
  EXPECT_EQ(build_semantic_graph(cloud).centers, graph.centers);
  LabelledCloud shuffled;
  std::vector<std::size_t> order(cloud.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  for (const auto i : order) shuffled.push_back_from(cloud, i);
  shuffled.has_labels = true;
  const auto again = build_semantic_graph(shuffled);
  std::set<std::pair<long, long>> kept_again;
  for (const auto& c : again.centers) kept_again.insert({std::lround(c.x() / 3.0), std::lround(c.y() / 3.0)});
  EXPECT_EQ(kept_again, kept);
}

TEST(SemanticGraph, EdgesJoinClustersWithin5mOfEachOtherWithLinearWeights) {
  LabelledCloud cloud;
  cloud.has_labels = true;
  // Three poles as vertical lines of points; nearest points 3 m (A-B) and 6 m (B-C) apart.
  auto pole = [&](float x) {
    for (int i = 0; i < 120; ++i) cloud.push_back({x, 0, 0.05F * static_cast<float>(i)}, 0, cls::kPole);
  };
  pole(0);
  pole(3);
  pole(9);
  const auto graph = build_semantic_graph(cloud);
  ASSERT_EQ(graph.size(), 3U);
  ASSERT_EQ(graph.edges.size(), 1U);
  EXPECT_EQ(graph.edges[0], (std::array<int, 2>{0, 1}));
  EXPECT_NEAR(graph.weights[0], 1.0 - 3.0 / 5.0, 1e-6);
}

TEST(SemanticGraph, ClusterDistanceIsTheExactNearestPointDistance) {
  std::mt19937 rng(5);
  LabelledCloud cloud;
  add_blob(cloud, rng, {0, 0, 0}, {2, 2, 2}, 600, cls::kBuilding);
  add_blob(cloud, rng, {5, 1, 0}, {1, 3, 1}, 500, cls::kVegetation);
  const auto clusters = extract_clusters(cloud);
  ASSERT_EQ(clusters.size(), 2U);
  double brute = 1e9;
  for (const auto i : clusters[0].points)
    for (const auto j : clusters[1].points)
      brute = std::min(brute, static_cast<double>((cloud.points[i] - cloud.points[j]).norm()));
  EXPECT_NEAR(cluster_distance(cloud, clusters[0], clusters[1], 5.0), brute, 1e-5);
  EXPECT_NEAR(cluster_distance(cloud, clusters[1], clusters[0], 5.0), brute, 1e-5);
  EXPECT_TRUE(std::isinf(cluster_distance(cloud, clusters[0], clusters[1], brute * 0.5)));
}

TEST(GraphJson, RoundTripIsExact) {
  std::mt19937 rng(6);
  LabelledCloud cloud;
  add_blob(cloud, rng, {10, 0, 0}, {2, 1, 0.7F}, 400, cls::kCar, 5);
  add_blob(cloud, rng, {12, 5, 1}, {1, 1, 1}, 400, cls::kVegetation);
  add_blob(cloud, rng, {-3, 2, 1}, {0.05F, 0.05F, 1}, 200, cls::kPole);
  SemanticGraph graph = build_semantic_graph(cloud);
  graph.pose = std::array<double, 12>{1, 0, 0, 1.0 / 3.0, 0, 1, 0, -2.5e-7, 0, 0, 1, 123.456789};
  ASSERT_FALSE(graph.edges.empty());
  testing::TempDir dir;
  write_graph_json(dir / "g.json", graph);
  const auto back = read_graph_json(dir / "g.json");
  EXPECT_EQ(back.nodes, graph.nodes);
  EXPECT_EQ(back.centers, graph.centers);
  EXPECT_EQ(back.edges, graph.edges);
  EXPECT_EQ(back.weights, graph.weights);
  EXPECT_EQ(back.pose, graph.pose);
}

TEST(GraphJson, ReadsTheOriginalSgprGraphs) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto graph = read_graph_json(testing::shared_file("models/sgpr/graph_0.json"));
  EXPECT_EQ(graph.size(), 38U);
  EXPECT_EQ(graph.nodes.front(), 0);
  EXPECT_EQ(graph.nodes.back(), 11);
  EXPECT_NEAR(graph.centers[0].x(), 5.191868782043457, 1e-15);
  ASSERT_TRUE(graph.pose.has_value());
  EXPECT_DOUBLE_EQ((*graph.pose)[0], 1.0);
  EXPECT_TRUE(graph.edges.empty());
}

TEST(GraphJson, MalformedGraphsAreClearErrors) {
  testing::TempDir dir;
  auto error_of = [&](const std::string& text) -> std::string {
    std::ofstream(dir / "bad.json") << text;
    try {
      (void)read_graph_json(dir / "bad.json");
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), dir / "bad.json");
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error_of("{not json").find("not valid JSON"), std::string::npos);
  EXPECT_NE(error_of(R"({"centers": []})").find("nodes"), std::string::npos);
  EXPECT_NE(error_of(R"({"nodes": [0], "centers": []})").find("1 nodes but 0 centers"), std::string::npos);
  EXPECT_NE(error_of(R"({"nodes": [12], "centers": [[0,0,0]]})").find("not a node class"), std::string::npos);
  EXPECT_NE(error_of(R"({"nodes": [1], "centers": [[0,0]]})").find("centers[0]"), std::string::npos);
  EXPECT_NE(error_of(R"({"nodes": [1], "centers": [[0,0,0]], "edges": [[0,3]], "weights": [1]})").find("edges[0]"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"nodes": [1], "centers": [[0,0,0]], "pose": [1,2]})").find("pose"), std::string::npos);
  // Integers beyond 32 bits are out of range, not wrapped (4294967299 = 2^32 + 3 once read as class 3).
  EXPECT_NE(error_of(R"({"nodes": [4294967299], "centers": [[0,0,0]]})").find("nodes[0] = 4294967299 is not a node class"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"nodes": [-4294967295], "centers": [[0,0,0]]})").find("not a node class"), std::string::npos);
  EXPECT_NE(error_of(R"({"nodes": [18446744073709551615], "centers": [[0,0,0]]})").find("not a node class"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"nodes": [1, 2], "centers": [[0,0,0], [1,1,1]], "edges": [[0, 4294967297]], "weights": [1]})")
                .find("edges[0] refers to a node that does not exist"),
            std::string::npos);
  EXPECT_NE(std::string(error_of("")).find("not valid JSON"), std::string::npos);
  // Finite but absurd numbers would overflow every distance the network computes.
  EXPECT_NE(error_of(R"({"nodes": [1], "centers": [[0,1e308,0]]})").find("centers[0] = 1e+308 is beyond +-100000"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"nodes": [1, 2], "centers": [[0,0,0], [1,1,1]], "edges": [[0, 1]], "weights": [3e38]})")
                .find("weights[0] = 3e+38 is beyond"),
            std::string::npos);
  try {
    (void)read_graph_json(dir / "missing.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  }
}

}  // namespace
}  // namespace saloam

namespace saloam {
namespace {

// Integration with the simulator: one 32-beam frame of the urban-loop preset.
TEST(SemanticGraph, SimulatedScanGivesAPlausibleDeterministicGraph) {
  SALOAM_REQUIRE_SHARED_DATA();
  testing::TempDir dir;
  SimulationOptions options;
  options.first_frame = 40;
  options.end_frame = 41;
  options.beams = 32;
  options.show_progress = false;
  simulate_sequence(options, dir.path());
  const auto cloud = read_scan(dir / "velodyne/000000.bin", dir / "labels/000000.label");
  const auto graph = build_semantic_graph(cloud);
  EXPECT_GE(graph.size(), 5U);
  EXPECT_LE(graph.size(), 100U);
  const std::set<int> classes(graph.nodes.begin(), graph.nodes.end());
  EXPECT_TRUE(classes.count(node_class::kBuilding) || classes.count(node_class::kVegetation));
  for (const auto& c : graph.centers) EXPECT_LT(c.head<2>().norm(), 130.0);
  for (std::size_t e = 0; e < graph.edges.size(); ++e) {
    EXPECT_LT(graph.edges[e][0], graph.edges[e][1]);
    EXPECT_GT(graph.weights[e], 0.0);
    EXPECT_LE(graph.weights[e], 1.0);
  }
  const auto again = build_semantic_graph(cloud);
  EXPECT_EQ(again.nodes, graph.nodes);
  EXPECT_EQ(again.centers, graph.centers);
  EXPECT_EQ(again.edges, graph.edges);
  // The graph embeds and scores itself as the same place.
  const auto network = SgprNetwork::load(testing::shared_file("models/sgpr/sgpr_kitti.sgw"));
  const auto h = network.embed(graph);
  EXPECT_GT(network.score(h, h), 0.5);
}

}  // namespace
}  // namespace saloam
