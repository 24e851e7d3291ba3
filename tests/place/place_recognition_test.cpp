// Place-recognition metrics on small known score sets.

#include <gtest/gtest.h>

#include <limits>

#include "saloam/place/place_recognition.hpp"

namespace saloam {
namespace {

TEST(PrecisionRecall, KnownScoreSet) {
  // Descending: P N P N P.
  const std::vector<double> scores{0.5, 0.9, 0.6, 0.7, 0.8};
  const std::vector<std::uint8_t> positive{1, 1, 0, 1, 0};
  const auto s = precision_recall(scores, positive);
  EXPECT_EQ(s.positives, 3U);
  EXPECT_EQ(s.negatives, 2U);
  ASSERT_EQ(s.curve.size(), 5U);
  EXPECT_DOUBLE_EQ(s.curve[0].threshold, 0.9);
  EXPECT_DOUBLE_EQ(s.curve[0].precision, 1.0);
  EXPECT_DOUBLE_EQ(s.curve[0].recall, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.curve[2].precision, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.curve[2].recall, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.curve[4].precision, 0.6);
  EXPECT_DOUBLE_EQ(s.curve[4].recall, 1.0);
  EXPECT_DOUBLE_EQ(s.max_f1, 0.75);  // at threshold 0.5: P 0.6, R 1
  EXPECT_DOUBLE_EQ(s.max_f1_threshold, 0.5);
  EXPECT_DOUBLE_EQ(s.precision_at_full_recall, 0.6);
  EXPECT_DOUBLE_EQ(s.recall_at_full_precision, 1.0 / 3.0);
}

TEST(PrecisionRecall, TiesFormOneThreshold) {
  const std::vector<double> scores{0.5, 0.5, 0.2};
  const std::vector<std::uint8_t> positive{1, 0, 0};
  const auto s = precision_recall(scores, positive);
  ASSERT_EQ(s.curve.size(), 2U);
  EXPECT_DOUBLE_EQ(s.curve[0].precision, 0.5);
  EXPECT_DOUBLE_EQ(s.recall_at_full_precision, 0.0);  // the positive never comes without the tied negative
  EXPECT_DOUBLE_EQ(s.precision_at_full_recall, 0.5);
  EXPECT_DOUBLE_EQ(s.max_f1, 2 * 0.5 * 1.0 / 1.5);
}

TEST(PrecisionRecall, PerfectSeparationAndNoPositives) {
  const auto s = precision_recall(std::vector<double>{0.9, 0.8, 0.1}, std::vector<std::uint8_t>{1, 1, 0});
  EXPECT_DOUBLE_EQ(s.max_f1, 1.0);
  EXPECT_DOUBLE_EQ(s.precision_at_full_recall, 1.0);
  EXPECT_DOUBLE_EQ(s.recall_at_full_precision, 1.0);
  const auto none = precision_recall(std::vector<double>{0.9}, std::vector<std::uint8_t>{0});
  EXPECT_EQ(none.positives, 0U);
  EXPECT_DOUBLE_EQ(none.max_f1, 0.0);
  EXPECT_TRUE(none.curve.empty());
  EXPECT_THROW((void)precision_recall(std::vector<double>{0.9}, std::vector<std::uint8_t>{}), std::invalid_argument);
}

TEST(PrecisionRecall, ANaNScoreIsRefusedNotLoopedOn) {
  // A NaN once made the threshold loop spin for ever, allocating curve points.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)precision_recall(std::vector<double>{0.9, nan, 0.1}, std::vector<std::uint8_t>{1, 0, 1}),
               std::invalid_argument);
  const double inf = std::numeric_limits<double>::infinity();
  const auto s = precision_recall(std::vector<double>{inf, -inf, 0.5}, std::vector<std::uint8_t>{1, 0, 1});
  EXPECT_EQ(s.curve.size(), 3U);
  EXPECT_DOUBLE_EQ(s.max_f1, 1.0);
}

TEST(PrecisionRecall, ThinnedCurveKeepsEndsAndBestPoint) {
  std::vector<double> scores;
  std::vector<std::uint8_t> positive;
  for (int i = 0; i < 1000; ++i) {
    scores.push_back(i * 0.001);
    positive.push_back(static_cast<std::uint8_t>((i * 7919) % 3 == 0 || i > 900));
  }
  const auto s = precision_recall(scores, positive);
  const auto thin = thin_curve(s, 50);
  EXPECT_LE(thin.size(), 2 * 50U + 3U);
  EXPECT_GE(thin.size(), 10U);
  for (std::size_t k = 1; k < thin.size(); ++k) EXPECT_LT(thin[k].threshold, thin[k - 1].threshold);
  EXPECT_EQ(thin.front().threshold, s.curve.front().threshold);
  EXPECT_EQ(thin.back().threshold, s.curve.back().threshold);
  bool has_best = false;
  for (const auto& p : thin) has_best |= p.threshold == s.max_f1_threshold;
  EXPECT_TRUE(has_best);
}

TEST(PlacePairs, ProtocolDistancesAndExclusion) {
  // Frames along x, 1 m apart, then back to the start.
  std::vector<Eigen::Vector3d> positions;
  for (int i = 0; i < 100; ++i) positions.emplace_back(i, 0, 0);
  positions.emplace_back(0.5, 2.0, 0);  // frame 100: revisit of frames 0..3 (within 3 m)
  PlaceEvalConfig config;
  const auto pairs = place_pairs(positions, config);
  for (const auto& p : pairs) {
    EXPECT_LT(p.candidate + config.exclude_recent, p.query);
    const double d = (positions[p.query] - positions[p.candidate]).norm();
    if (p.positive)
      EXPECT_LE(d, 3.0);
    else
      EXPECT_GT(d, 20.0);
  }
  std::size_t revisit_positives = 0;
  for (const auto& p : pairs) revisit_positives += (p.query == 100 && p.positive);
  EXPECT_EQ(revisit_positives, 3U);  // frames 0, 1, 2 (frame 3 is 3.2 m away)
  // Frames 51..99 have no positives (the path never comes back) but negatives.
  std::size_t positives = 0;
  for (const auto& p : pairs) positives += p.positive;
  EXPECT_EQ(positives, 3U);
  EXPECT_FALSE(pairs.empty());
}

TEST(PlacePairs, NegativeShareKeepsEveryPositiveAndAFixedSubsetOfNegatives) {
  std::vector<Eigen::Vector3d> positions;
  for (int i = 0; i < 400; ++i) positions.emplace_back(i, 0, 0);
  for (int i = 0; i < 20; ++i) positions.emplace_back(i, 1.0, 0);  // a second pass over the first 20 m
  PlaceEvalConfig all;
  PlaceEvalConfig sampled = all;
  sampled.negative_share = 0.05;
  const auto full = place_pairs(positions, all);
  const auto part = place_pairs(positions, sampled);
  std::size_t full_pos = 0, full_neg = 0, part_pos = 0, part_neg = 0;
  for (const auto& p : full) (p.positive ? full_pos : full_neg) += 1;
  for (const auto& p : part) (p.positive ? part_pos : part_neg) += 1;
  EXPECT_EQ(part_pos, full_pos);
  EXPECT_GT(full_pos, 0U);
  const double share = static_cast<double>(part_neg) / static_cast<double>(full_neg);
  EXPECT_NEAR(share, 0.05, 0.005) << part_neg << " of " << full_neg;
  // The same pairs every time, and a subset of the full list.
  const auto again = place_pairs(positions, sampled);
  ASSERT_EQ(again.size(), part.size());
  for (std::size_t k = 0; k < part.size(); ++k) {
    EXPECT_EQ(again[k].query, part[k].query);
    EXPECT_EQ(again[k].candidate, part[k].candidate);
  }
}

}  // namespace
}  // namespace saloam
