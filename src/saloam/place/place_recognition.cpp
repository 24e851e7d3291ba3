#include "saloam/place/place_recognition.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>

#include "saloam/core/hash.hpp"

namespace saloam {

namespace {
// A number in [0, 1) fixed by the pair (i, j).
double pair_draw(std::size_t i, std::size_t j) {
  return hash_to_unit(mix64((static_cast<std::uint64_t>(i) << 32) ^ static_cast<std::uint64_t>(j)));
}
}  // namespace

std::vector<PlacePair> place_pairs(std::span<const Eigen::Vector3d> positions, const PlaceEvalConfig& config) {
  std::vector<PlacePair> pairs;
  const double pos_sq = config.positive_distance * config.positive_distance;
  const double neg_sq = config.negative_distance * config.negative_distance;
  for (std::size_t i = config.exclude_recent + 1; i < positions.size(); ++i) {
    for (std::size_t j = 0; j + config.exclude_recent < i; ++j) {
      const double d_sq = (positions[i] - positions[j]).squaredNorm();
      if (d_sq <= pos_sq)
        pairs.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j), true});
      else if (d_sq > neg_sq && (config.negative_share >= 1.0 || pair_draw(i, j) < config.negative_share))
        pairs.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j), false});
    }
  }
  return pairs;
}

PrSummary precision_recall(std::span<const double> scores, std::span<const std::uint8_t> positive) {
  if (scores.size() != positive.size()) throw std::invalid_argument("precision_recall: sizes differ");
  for (std::size_t k = 0; k < scores.size(); ++k) {
    if (std::isnan(scores[k])) throw std::invalid_argument("precision_recall: score " + std::to_string(k) + " is NaN");
  }
  PrSummary s;
  for (const auto p : positive) (p ? s.positives : s.negatives) += 1;
  if (s.positives == 0) return s;
  std::vector<std::size_t> order(scores.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return scores[a] > scores[b]; });
  std::size_t tp = 0, fp = 0;
  const auto total_pos = static_cast<double>(s.positives);
  for (std::size_t k = 0; k < order.size();) {
    const double threshold = scores[order[k]];
    // All pairs scoring exactly `threshold` are accepted together.
    // (The first always: k advances whatever the scores are.)
    do {
      (positive[order[k]] ? tp : fp) += 1;
      ++k;
    } while (k < order.size() && scores[order[k]] == threshold);
    PrPoint point{threshold, static_cast<double>(tp) / static_cast<double>(tp + fp), static_cast<double>(tp) / total_pos};
    s.curve.push_back(point);
    const double f1 = tp > 0 ? 2 * point.precision * point.recall / (point.precision + point.recall) : 0.0;
    if (f1 > s.max_f1) {
      s.max_f1 = f1;
      s.max_f1_threshold = threshold;
      s.max_f1_precision = point.precision;
      s.max_f1_recall = point.recall;
    }
    if (fp == 0) s.recall_at_full_precision = point.recall;
    if (tp == s.positives && s.precision_at_full_recall == 0) s.precision_at_full_recall = point.precision;
  }
  return s;
}

std::vector<PrPoint> thin_curve(const PrSummary& summary, std::size_t max_points) {
  const auto& curve = summary.curve;
  if (curve.size() <= max_points || max_points < 2) return curve;
  // Keep a point once precision or recall has moved by a step since the last
  // kept one: even detail along the drawn curve, wherever the scores crowd.
  const double step = 1.0 / static_cast<double>(max_points);
  std::vector<PrPoint> out{curve.front()};
  for (std::size_t k = 1; k + 1 < curve.size(); ++k) {
    const auto& p = curve[k];
    const bool moved = std::abs(p.recall - out.back().recall) >= step || std::abs(p.precision - out.back().precision) >= step;
    if (moved || p.threshold == summary.max_f1_threshold) out.push_back(p);
  }
  out.push_back(curve.back());
  return out;
}

}  // namespace saloam
