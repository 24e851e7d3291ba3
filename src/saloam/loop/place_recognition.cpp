#include "saloam/loop/place_recognition.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace saloam {

std::vector<PlacePair> place_pairs(std::span<const Eigen::Vector3d> positions, const PlaceEvalConfig& config) {
  std::vector<PlacePair> pairs;
  const double pos_sq = config.positive_distance * config.positive_distance;
  const double neg_sq = config.negative_distance * config.negative_distance;
  for (std::size_t i = config.exclude_recent + 1; i < positions.size(); ++i) {
    for (std::size_t j = 0; j + config.exclude_recent < i; ++j) {
      const double d_sq = (positions[i] - positions[j]).squaredNorm();
      if (d_sq <= pos_sq)
        pairs.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j), true});
      else if (d_sq > neg_sq)
        pairs.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j), false});
    }
  }
  return pairs;
}

PrSummary precision_recall(std::span<const double> scores, std::span<const std::uint8_t> positive) {
  if (scores.size() != positive.size()) throw std::invalid_argument("precision_recall: sizes differ");
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
    for (; k < order.size() && scores[order[k]] == threshold; ++k) (positive[order[k]] ? tp : fp) += 1;
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
  std::vector<PrPoint> out;
  for (std::size_t k = 0; k < max_points; ++k) {
    const std::size_t index = k * (curve.size() - 1) / (max_points - 1);
    if (out.empty() || out.back().threshold != curve[index].threshold) out.push_back(curve[index]);
    // Keep the max-F1 point where it falls between two samples.
    const std::size_t next = (k + 1) * (curve.size() - 1) / (max_points - 1);
    if (k + 1 < max_points)
      for (std::size_t m = index + 1; m < next; ++m)
        if (curve[m].threshold == summary.max_f1_threshold) out.push_back(curve[m]);
  }
  return out;
}

}  // namespace saloam
