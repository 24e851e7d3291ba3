#pragma once
// The score of semantic labels against ground truth, as SemanticKITTI's API
// computes it: a confusion matrix over the learning classes, per-class IoU
// and the mean IoU over the classes present in the truth. Used for the
// simulator's emulated network output, `saloam segment` and the
// segmentation network's training.

#include <array>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "saloam/core/semantic_classes.hpp"

namespace saloam {

/// Confusion matrix over the SemanticKITTI learning classes (0 = ignored).
class SegmentationScore {
 public:
  /// Adds raw-id labels (ground truth, prediction) of one scan.
  void add(const std::vector<std::uint16_t>& truth, const std::vector<std::uint16_t>& predicted);
  /// IoU of learning class c (NaN when the class appears in neither).
  [[nodiscard]] double iou(int learning_class) const;
  /// Mean IoU over the classes present in the ground truth.
  [[nodiscard]] double miou() const;
  /// Fraction of (non-ignored) points labelled correctly.
  [[nodiscard]] double accuracy() const;
  [[nodiscard]] std::uint64_t truth_count(int learning_class) const;
  /// mIoU, accuracy, per-class IoU and points (classes present in either
  /// labelling, by name) and the confusion matrix (rows: truth, columns:
  /// prediction, learning classes 0..19), from which scores over several
  /// runs are pooled.
  [[nodiscard]] nlohmann::json to_json() const;

 private:
  std::array<std::array<std::uint64_t, kNumLearningClasses>, kNumLearningClasses> confusion_{};
};

}  // namespace saloam
