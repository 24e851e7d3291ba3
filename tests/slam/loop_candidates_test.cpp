// Loop-candidate generation (Eq. 3) and its seeded random draw.

#include <algorithm>
#include <set>

#include <gtest/gtest.h>

#include "saloam/slam/loop_candidates.hpp"

namespace saloam {
namespace {

/// The gate of Table I (config/paper.yaml's loop.sigma 0.05); the rest as configured by default.
CandidateGate table_one_gate() {
  LoopClosureConfig config;
  config.sigma = 0.05;
  return CandidateGate::from_config(config);
}

TEST(SearchRadius, FollowsEquationThree) {
  const CandidateGate gate = table_one_gate();  // sigma 0.05, delta_min 15, delta_max 100
  EXPECT_DOUBLE_EQ(search_radius(gate, 0.0), 15.0);     // bounded below
  EXPECT_DOUBLE_EQ(search_radius(gate, 200.0), 15.0);   // 0.05 * 200 = 10 < 15
  EXPECT_DOUBLE_EQ(search_radius(gate, 1000.0), 50.0);  // sigma * d
  EXPECT_DOUBLE_EQ(search_radius(gate, 5000.0), 100.0); // bounded above
}

TEST(SearchRadius, MatchesTheConfig) {
  LoopClosureConfig config;
  config.sigma = 0.1;
  config.delta_min = 5;
  config.delta_max = 20;
  config.num_candidates = 7;
  config.exclude_recent_distance = 30;
  const CandidateGate gate = CandidateGate::from_config(config);
  EXPECT_DOUBLE_EQ(search_radius(gate, 100.0), 10.0);
  EXPECT_EQ(gate.max_candidates, 7u);
  EXPECT_DOUBLE_EQ(gate.exclude_recent_distance, 30.0);
}

// Keyframes 1 m apart along x, then the query.
std::vector<KeyframePlace> along_x(int n) {
  std::vector<KeyframePlace> places;
  for (int i = 0; i < n; ++i) places.push_back({Eigen::Vector3d(i, 0, 0), static_cast<double>(i)});
  return places;
}

TEST(LoopCandidates, GatesByRadiusAndRecentTravel) {
  CandidateGate gate = CandidateGate::from_config(LoopClosureConfig{});
  gate.delta_min = 15;
  gate.sigma = 0.0;  // radius delta_min everywhere
  gate.exclude_recent_distance = 50;
  std::mt19937_64 rng(1);
  const auto earlier = along_x(100);
  // The query is back at x = 10 after 200 m of travel (a loop).
  const KeyframePlace query{Eigen::Vector3d(10, 3, 0), 200.0};
  const auto c = loop_candidates(query, earlier, gate, rng);
  // |x - 10|^2 + 9 < 225  <=>  |x - 10| < 14.7: x in 0..24.
  ASSERT_EQ(c.size(), 25u);
  EXPECT_EQ(c.front(), 0u);
  EXPECT_EQ(c.back(), 24u);
  // Travelled less than 50 m before the query: never candidates, however close.
  const KeyframePlace fresh{Eigen::Vector3d(99, 0, 0), 120.0};
  const auto near = loop_candidates(fresh, earlier, gate, rng);
  for (const auto j : near) EXPECT_LE(earlier[j].travelled, 70.0);
}

TEST(LoopCandidates, RadiusGrowsWithTravelledDistance) {
  CandidateGate gate = table_one_gate();
  gate.exclude_recent_distance = 0;
  std::mt19937_64 rng(1);
  const std::vector<KeyframePlace> earlier{{Eigen::Vector3d(0, 0, 0), 0.0}};
  // 40 m away: found only when travelled enough for 0.05 d > 40 (d > 800 m).
  EXPECT_TRUE(loop_candidates({Eigen::Vector3d(40, 0, 0), 700.0}, earlier, gate, rng).empty());
  EXPECT_EQ(loop_candidates({Eigen::Vector3d(40, 0, 0), 900.0}, earlier, gate, rng).size(), 1u);
}

TEST(LoopCandidates, DrawsAtMostNCandiReproducibly) {
  CandidateGate gate = CandidateGate::from_config(LoopClosureConfig{});
  gate.delta_min = 1000;  // everything qualifies
  gate.exclude_recent_distance = 0;
  gate.max_candidates = 64;
  const auto earlier = along_x(500);
  const KeyframePlace query{Eigen::Vector3d(0, 0, 0), 1000.0};
  std::mt19937_64 a(42), b(42), c(43);
  const auto first = loop_candidates(query, earlier, gate, a);
  const auto same = loop_candidates(query, earlier, gate, b);
  const auto other = loop_candidates(query, earlier, gate, c);
  ASSERT_EQ(first.size(), 64u);
  EXPECT_EQ(first, same);  // same seed, same draw
  EXPECT_NE(first, other);
  EXPECT_TRUE(std::is_sorted(first.begin(), first.end()));
  EXPECT_EQ(std::set<std::size_t>(first.begin(), first.end()).size(), 64u);  // no repeats
  // A random draw, not the nearest 64: it reaches far into the 500.
  EXPECT_GT(first.back(), 300u);
  // Every candidate has about the same chance: over many draws each of the
  // 500 is picked about 64 / 500 of the time.
  std::vector<int> picked(500, 0);
  std::mt19937_64 rng(7);
  const int draws = 2000;
  for (int d = 0; d < draws; ++d)
    for (const auto j : loop_candidates(query, earlier, gate, rng)) ++picked[j];
  const double expected = draws * 64.0 / 500.0;  // 256
  for (const int count : picked) {
    EXPECT_GT(count, 0.7 * expected);
    EXPECT_LT(count, 1.3 * expected);
  }
}

}  // namespace
}  // namespace saloam
