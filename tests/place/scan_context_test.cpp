// Scan Context: descriptor, yaw invariance, place discrimination, retrieval.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/Geometry>

#include "saloam/place/scan_context.hpp"

namespace saloam {
namespace {

/// A synthetic street scene: ground, box "buildings" and "trees" at random
/// places around the sensor (different seeds give different places).
std::vector<Eigen::Vector3f> scene(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0F, 1.0F);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 20000; ++i) points.emplace_back(60 * u(rng), 60 * u(rng), -1.73F);
  for (int b = 0; b < 25; ++b) {
    const Eigen::Vector3f centre(70 * u(rng), 70 * u(rng), 0);
    const float height = 4 + 10 * (u(rng) + 1);
    const float size = 2 + 3 * (u(rng) + 1);
    for (int i = 0; i < 1500; ++i) {
      const Eigen::Vector3f p = centre + Eigen::Vector3f(size * u(rng), size * u(rng), 0);
      points.emplace_back(p.x(), p.y(), -1.73F + height * 0.5F * (u(rng) + 1));
    }
  }
  return points;
}

std::vector<Eigen::Vector3f> yawed(const std::vector<Eigen::Vector3f>& points, double yaw) {
  const Eigen::Matrix3f r = Eigen::AngleAxisf(static_cast<float>(yaw), Eigen::Vector3f::UnitZ()).toRotationMatrix();
  std::vector<Eigen::Vector3f> out;
  for (const auto& p : points) out.push_back(r * p);
  return out;
}

TEST(ScanContext, DescriptorHoldsMaxHeightPerPolarBin) {
  std::vector<Eigen::Vector3f> points{{10, 0.1F, 1}, {10.5F, 0.2F, 3}, {0, 30, -1}, {90, 0, 5}};
  const auto sc = make_scan_context(points);
  ASSERT_EQ(sc.descriptor.rows(), 20);
  ASSERT_EQ(sc.descriptor.cols(), 60);
  EXPECT_FLOAT_EQ(sc.descriptor(2, 0), 5.0F);    // 10 m -> ring 2 (4 m rings), max z + 2
  EXPECT_FLOAT_EQ(sc.descriptor(7, 15), 1.0F);   // 30 m, 90 degrees -> ring 7, sector 15
  EXPECT_EQ((sc.descriptor.array() != 0).count(), 2);  // the point at 90 m is out of range
  EXPECT_NEAR(sc.ring_key[2], 5.0 / 60.0, 1e-6);
}

TEST(ScanContext, YawedCopyIsTheSamePlace) {
  const auto points = scene(1);
  const auto sc = make_scan_context(points);
  // A rotation by whole sectors is a pure column shift.
  const auto exact = scan_context_distance(sc, make_scan_context(yawed(points, 10 * 2 * std::numbers::pi / 60 + 1e-4)));
  EXPECT_LT(exact.distance, 1e-3);
  EXPECT_EQ(exact.shift, 10);
  // Arbitrary yaws: still far closer than any other place.
  const auto other = scan_context_distance(sc, make_scan_context(scene(2)));
  for (const double yaw : {0.3, 1.7, 3.0, 4.4, -2.2}) {
    const auto m = scan_context_distance(sc, make_scan_context(yawed(points, yaw)));
    EXPECT_LT(m.distance, 0.15) << yaw;
    EXPECT_LT(m.distance, 0.5 * other.distance) << yaw;
    // Ring keys hardly depend on yaw (only through bin boundaries).
    EXPECT_LT((make_scan_context(yawed(points, yaw)).ring_key - sc.ring_key).norm(),
              0.5 * (make_scan_context(scene(2)).ring_key - sc.ring_key).norm());
  }
  EXPECT_GT(other.distance, 0.2);
  EXPECT_NEAR(scan_context_distance(sc, sc).distance, 0.0, 1e-6);
}

TEST(ScanContext, RingKeyRetrievalFindsTheRevisit) {
  std::vector<ScanContext> database;
  for (unsigned s = 10; s < 30; ++s) database.push_back(make_scan_context(scene(s)));
  const auto query = make_scan_context(yawed(scene(17), 2.0));
  const auto candidates = ring_key_candidates(query, database, database.size(), 3);
  ASSERT_EQ(candidates.size(), 3U);
  EXPECT_EQ(candidates[0], 7U);
  // Only the first `searchable` entries are considered.
  for (const auto c : ring_key_candidates(query, database, 5, 10)) EXPECT_LT(c, 5U);
  EXPECT_EQ(ring_key_candidates(query, database, 5, 10).size(), 5U);
}

TEST(ScanContext, EmptyScansHaveDistanceOne) {
  const auto empty = make_scan_context(std::vector<Eigen::Vector3f>{});
  EXPECT_DOUBLE_EQ(scan_context_distance(empty, make_scan_context(scene(1))).distance, 1.0);
}

}  // namespace
}  // namespace saloam
