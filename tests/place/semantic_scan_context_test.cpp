// Semantic Scan Context: class codes, descriptor cells, the two-step
// alignment on a rotated and shifted copy of a scan, place discrimination,
// and the PlaceRecognizer's "ssc" detector (T_candidate<-query).

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/Geometry>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/place/semantic_scan_context.hpp"

namespace saloam {
namespace {

/// A synthetic labelled street scene in a world frame: road and sidewalk
/// ground, terrain, building blocks along both sides, poles, trunks with
/// vegetation crowns, a fence and parked cars; a different seed gives a
/// different place.
LabelledCloud scene(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0F, 1.0F);
  LabelledCloud cloud;
  cloud.has_labels = true;
  auto add = [&](float x, float y, float z, std::uint16_t label) { cloud.push_back({x, y, z}, 0.3F, label); };
  const float street_angle = 0.6F * u(rng);  // the street's direction differs between places
  const Eigen::Vector2f along(std::cos(street_angle), std::sin(street_angle)), across(-along.y(), along.x());
  for (int i = 0; i < 30000; ++i) {
    const float s = 70 * u(rng), t = 40 * u(rng);
    const std::uint16_t label = std::abs(t) < 5 ? cls::kRoad : std::abs(t) < 8 ? cls::kSidewalk : cls::kTerrain;
    const Eigen::Vector2f p = s * along + t * across;
    add(p.x(), p.y(), -1.73F, label);
  }
  for (int b = 0; b < 14; ++b) {  // building blocks 10..30 m from the street's axis
    const float side = b % 2 ? 1.0F : -1.0F;
    const Eigen::Vector2f centre = 60 * u(rng) * along + side * (16 + 6 * u(rng)) * across;
    const float half_length = 4 + 3 * (u(rng) + 1), half_depth = 3 + 2 * (u(rng) + 1);
    for (int i = 0; i < 1500; ++i) {
      const Eigen::Vector2f p = centre + half_length * u(rng) * along + half_depth * u(rng) * across;
      add(p.x(), p.y(), -1.73F + 5 * (u(rng) + 1), cls::kBuilding);
    }
  }
  for (int k = 0; k < 30; ++k) {  // poles and trees along the sidewalks
    const float side = k % 2 ? 1.0F : -1.0F;
    const Eigen::Vector2f base = 65 * u(rng) * along + side * (6 + 1.5F * u(rng)) * across;
    const bool tree = k % 3 == 0;
    for (int i = 0; i < 120; ++i) {
      add(base.x() + 0.1F * u(rng), base.y() + 0.1F * u(rng), -1.73F + 2.5F * (u(rng) + 1),
          tree ? cls::kTrunk : cls::kPole);
    }
    if (!tree) continue;
    for (int i = 0; i < 400; ++i) add(base.x() + 2 * u(rng), base.y() + 2 * u(rng), 4 + 1.5F * u(rng), cls::kVegetation);
  }
  for (int i = 0; i < 2000; ++i) {  // a fence on one side
    const Eigen::Vector2f p = 30 * u(rng) * along - 9.0F * across;
    add(p.x(), p.y(), -1.73F + 0.7F * (u(rng) + 1), cls::kFence);
  }
  for (int c = 0; c < 6; ++c) {  // parked cars: ignored by SSC
    const Eigen::Vector2f centre = 50 * u(rng) * along + 4.0F * across;
    for (int i = 0; i < 300; ++i) add(centre.x() + 2 * u(rng), centre.y() + u(rng), -1 + 0.7F * u(rng), cls::kCar);
  }
  return cloud;
}

/// The scene seen by a sensor at (x, y) with heading yaw in the scene's
/// frame: p_sensor = R(yaw)^T (p - (x, y, 0)).
LabelledCloud seen_from(const LabelledCloud& scene_points, double yaw, double x, double y) {
  const Eigen::Isometry3f sensor_from_scene =
      (Eigen::Translation3f(static_cast<float>(x), static_cast<float>(y), 0) *
       Eigen::AngleAxisf(static_cast<float>(yaw), Eigen::Vector3f::UnitZ()))
          .inverse();
  LabelledCloud out = scene_points;
  for (auto& p : out.points) p = sensor_from_scene * p;
  return out;
}

double angle_difference(double a, double b) { return std::abs(std::remainder(a - b, 2 * std::numbers::pi)); }

TEST(SemanticScanContext, ClassCodesFollowThePaperPriority) {
  EXPECT_EQ(ssc_class_code(cls::kTerrain), 1);
  EXPECT_EQ(ssc_class_code(cls::kRoad), 2);
  EXPECT_EQ(ssc_class_code(cls::kLaneMarking), 2);
  EXPECT_EQ(ssc_class_code(cls::kVegetation), 6);
  EXPECT_EQ(ssc_class_code(cls::kBuilding), 7);
  EXPECT_EQ(ssc_class_code(cls::kTrafficSign), 11);
  for (const std::uint16_t ignored : {cls::kUnlabeled, cls::kCar, cls::kMovingCar, cls::kPerson, cls::kTruck,
                                      cls::kOtherStructure, cls::kOtherObject})
    EXPECT_EQ(ssc_class_code(ignored), 0) << ignored;
}

TEST(SemanticScanContext, CellsHoldTheHighestPriorityClass) {
  LabelledCloud cloud;
  cloud.has_labels = true;
  cloud.push_back({10.1F, 0.05F, -1.7F}, 0, cls::kRoad);   // 10.1 m, 0.3 deg: ring 2, sector 0
  cloud.push_back({10.3F, 0.06F, 2.0F}, 0, cls::kPole);    // same cell, higher priority
  cloud.push_back({10.2F, 0.07F, 0.0F}, 0, cls::kCar);     // ignored
  cloud.push_back({0.05F, 20.0F, 0.0F}, 0, cls::kBuilding);  // 20 m, 89.9 deg: ring 8, sector 89
  cloud.push_back({2.0F, 0.0F, 0.0F}, 0, cls::kBuilding);    // inside the inner radius
  cloud.push_back({70.0F, 0.0F, 0.0F}, 0, cls::kBuilding);   // beyond the outer radius
  const SscConfig config;
  const auto d = make_semantic_scan_context(cloud, config);
  ASSERT_EQ(d.cells.size(), static_cast<std::size_t>(config.rings * config.sectors));
  auto cell = [&](int ring, int sector) { return d.cells[static_cast<std::size_t>(ring * config.sectors + sector)]; };
  EXPECT_EQ(cell(2, 0), ssc_class_code(cls::kPole));
  EXPECT_EQ(cell(8, 89), ssc_class_code(cls::kBuilding));
  EXPECT_EQ(std::count_if(d.cells.begin(), d.cells.end(), [](std::uint8_t c) { return c != 0; }), 2);
  // Key points: nearest key-class point per sector (the pole at 10.3 m, the buildings at 2 and 20 m).
  EXPECT_NEAR(d.key_range[0], 2.0F, 1e-5);
  EXPECT_NEAR(d.key_range[89], 20.0F, 1e-3);
  EXPECT_DOUBLE_EQ(ssc_similarity(d.cells, d.cells), 1.0);
  // Without labels nothing is kept.
  cloud.has_labels = false;
  const auto empty = make_semantic_scan_context(cloud, config);
  EXPECT_TRUE(empty.points.empty());
  EXPECT_DOUBLE_EQ(ssc_similarity(empty.cells, empty.cells), 0.0);
}

TEST(SemanticScanContext, AlignmentRecoversAKnownYawAndShift) {
  const LabelledCloud query = scene(1);
  const double sector = 2 * std::numbers::pi / SscConfig{}.key_sectors;
  struct Case {
    double yaw, x, y;
  };
  for (const Case c : {Case{0.0, 0.0, 0.0}, Case{0.7, 1.5, -2.0}, Case{-2.2, -3.0, 1.0}, Case{std::numbers::pi, 2.5, 2.5}}) {
    // The candidate's sensor sits at (x, y) with heading yaw in the query's frame: T_query<-candidate.
    const LabelledCloud candidate = seen_from(query, c.yaw, c.x, c.y);
    const auto q = make_semantic_scan_context(query);
    const auto k = make_semantic_scan_context(candidate);
    const SscMatch m = match_semantic_scan_contexts(q, k);
    EXPECT_LT(angle_difference(m.alignment.yaw, c.yaw), sector) << c.yaw;
    EXPECT_LT((m.alignment.translation - Eigen::Vector2d(c.x, c.y)).norm(), 0.5) << c.yaw << " " << c.x << " " << c.y;
    EXPECT_FALSE(m.alignment.translation_capped);
    EXPECT_GT(m.score, 0.8) << c.yaw;
  }
}

TEST(SemanticScanContext, DifferentPlacesScoreLower) {
  const auto a = make_semantic_scan_context(scene(1));
  const auto a_moved = make_semantic_scan_context(seen_from(scene(1), 1.0, 2.0, -1.0));
  const double same = match_semantic_scan_contexts(a, a_moved).score;
  for (const unsigned seed : {2U, 3U, 4U}) {
    const auto other = make_semantic_scan_context(seen_from(scene(seed), 1.0, 2.0, -1.0));
    const double different = match_semantic_scan_contexts(a, other).score;
    EXPECT_LT(different, same - 0.2) << seed;
  }
}

TEST(SemanticScanContext, DeterministicAndSymmetricInItsAlignment) {
  const auto a = make_semantic_scan_context(scene(5));
  const auto b = make_semantic_scan_context(seen_from(scene(5), -0.4, 1.0, 2.0));
  const SscMatch ab = match_semantic_scan_contexts(a, b), again = match_semantic_scan_contexts(a, b);
  EXPECT_EQ(ab.score, again.score);
  EXPECT_EQ(ab.alignment.yaw, again.alignment.yaw);
  EXPECT_EQ(ab.alignment.translation, again.alignment.translation);
  // b onto a is the inverse motion.
  const SscMatch ba = match_semantic_scan_contexts(b, a);
  EXPECT_LT(angle_difference(ba.alignment.yaw, -ab.alignment.yaw), 2 * std::numbers::pi / 360);
  const Eigen::Vector2d inverse = -(Eigen::Rotation2Dd(-ab.alignment.yaw) * ab.alignment.translation);
  EXPECT_LT((ba.alignment.translation - inverse).norm(), 0.5);
}

TEST(SemanticScanContext, RecognizerReportsCandidateFromQuery) {
  const PlaceRecognizer recognizer(PlaceDetector::kSsc, std::nullopt);
  EXPECT_EQ(parse_place_detector("ssc"), PlaceDetector::kSsc);
  EXPECT_EQ(place_detector_name(PlaceDetector::kSsc), "ssc");
  EXPECT_TRUE(needs_labels(PlaceDetector::kSsc));
  EXPECT_FALSE(uses_sgpr(PlaceDetector::kSsc));
  // The candidate's sensor at the scene's origin; the query's at (3, -1)
  // with heading 0.5 in the candidate's frame: T_candidate<-query.
  const LabelledCloud query = scene(1);
  const LabelledCloud query_moved = seen_from(query, 0.5, 3.0, -1.0);
  const PlaceDescriptor q = recognizer.describe(query_moved);
  const PlaceDescriptor c = recognizer.describe(query);
  const std::vector<const PlaceDescriptor*> candidates{&c};
  const auto matches = recognizer.match(q, candidates);
  ASSERT_EQ(matches.size(), 1U);
  ASSERT_TRUE(matches[0].yaw && matches[0].translation);
  EXPECT_LT(angle_difference(*matches[0].yaw, 0.5), 2 * std::numbers::pi / 360);
  EXPECT_LT((*matches[0].translation - Eigen::Vector2d(3.0, -1.0)).norm(), 0.5);
  EXPECT_EQ(matches[0].score, matches[0].ssc_score);
  EXPECT_GT(matches[0].score, 0.8);
}

}  // namespace
}  // namespace saloam
