#pragma once
// Class shares of labelled scans: the fraction of all returned points that
// carry each raw SemanticKITTI label, and SemanticKITTI's own shares to
// compare them with (the `content` block of semantic-kitti.yaml: ratios to
// the total number of points, unlabeled and outliers included).

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace saloam {

class SimulatedSequence;

/// Reference share of one raw label in SemanticKITTI.
struct ReferenceShare {
  std::uint16_t label = 0;
  double share = 0;  ///< fraction of all points
};

/// SemanticKITTI's shares of its eight largest classes (semantic-kitti.yaml
/// `content`): vegetation 26.7 %, road 19.9 %, sidewalk 14.4 %, building
/// 13.3 %, terrain 7.8 %, fence 7.2 %, car 4.1 %, parking 1.5 %. Together
/// 95 % of all points; the simulator's world is tuned to these.
std::span<const ReferenceShare> semantic_kitti_shares();

/// Relative band within which a simulated share counts as KITTI-like:
/// within +-30 % of SemanticKITTI's share.
inline constexpr double kShareTolerance = 0.30;

/// Point counts per raw label (0..259), accumulated over scans.
class ClassShares {
 public:
  void add(std::span<const std::uint16_t> labels);
  void merge(const ClassShares& other);
  [[nodiscard]] std::uint64_t total() const { return total_; }
  [[nodiscard]] std::uint64_t count(std::uint16_t label) const;
  /// Fraction of all points with this label (0 when there are none).
  [[nodiscard]] double share(std::uint16_t label) const;
  /// share(label) / reference - 1 for a SemanticKITTI reference class.
  [[nodiscard]] static double relative_error(double share, double reference) { return share / reference - 1.0; }

 private:
  static constexpr std::size_t kLabels = 260;
  std::array<std::uint64_t, kLabels> counts_{};
  std::uint64_t total_ = 0;
};

/// A table of the reference classes: share here, SemanticKITTI's, the
/// relative difference and whether it lies within kShareTolerance; then the
/// other labels with at least 0.1 % of the points.
std::string format_class_shares(const ClassShares& shares);

/// Ground-truth class shares of every frame of a simulated sequence
/// (rendered in memory, nothing written).
ClassShares measure_class_shares(const SimulatedSequence& sequence, bool show_progress = false);

}  // namespace saloam
