#pragma once
// Place-recognition evaluation (SGPR's protocol): every frame is compared with
// the earlier frames except the most recent ones; a pair is a true match when
// the two scans are within `positive_distance`, a true non-match beyond
// `negative_distance`, and ignored in between. Scores are swept over all
// pairs to give a precision-recall curve.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace saloam {

struct PlaceEvalConfig {
  double positive_distance = 3.0;   ///< [m] pairs closer than this are matches
  double negative_distance = 20.0;  ///< [m] pairs farther than this are non-matches
  std::size_t exclude_recent = 50;  ///< frames just before the query that are not compared
  /// Share of the negative pairs kept, drawn per pair by a fixed hash of its
  /// frame indices (the same pairs in every run). 1 = all pairs. SGPR's own
  /// pair lists keep 0.5 % of the negatives, and every pair within 3 m
  /// however close in time (exclude_recent 0): an easier protocol.
  double negative_share = 1.0;
};

/// One evaluated pair: query frame, earlier candidate frame, truth.
struct PlacePair {
  std::uint32_t query = 0;
  std::uint32_t candidate = 0;
  bool positive = false;
};

/// All pairs (i, j) with j < i - exclude_recent whose distance is within
/// positive_distance (positive) or beyond negative_distance (negative; a
/// `negative_share` of them), ordered by query then candidate. Distances are
/// between the positions given.
std::vector<PlacePair> place_pairs(std::span<const Eigen::Vector3d> positions, const PlaceEvalConfig& config = {});

struct PrPoint {
  double threshold = 0;  ///< pairs with score >= threshold are predicted matches
  double precision = 0;
  double recall = 0;
};

struct PrSummary {
  std::size_t positives = 0, negatives = 0;
  std::vector<PrPoint> curve;  ///< one point per distinct score, decreasing threshold
  double max_f1 = 0;
  double max_f1_threshold = 0;
  double max_f1_precision = 0, max_f1_recall = 0;
  double precision_at_full_recall = 0;  ///< precision when every positive is accepted
  double recall_at_full_precision = 0;  ///< largest recall with no false positive
};

/// Precision-recall analysis of scores (higher = more similar) against truth.
/// Ties are handled as one threshold. With no positives all metrics are 0.
/// A score that is not a number throws std::invalid_argument (it has no
/// place in the order; the callers' describers never give one).
PrSummary precision_recall(std::span<const double> scores, std::span<const std::uint8_t> positive);

/// A thinned curve for plots and CSV: a point is kept when precision or
/// recall moved by 1 / max_points since the last kept one (so about
/// max_points to 2 max_points points), plus the first, last and max-F1 points.
std::vector<PrPoint> thin_curve(const PrSummary& summary, std::size_t max_points);

}  // namespace saloam
