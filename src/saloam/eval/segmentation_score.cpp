#include "saloam/eval/segmentation_score.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "saloam/core/error.hpp"

namespace saloam {

void SegmentationScore::add(const std::vector<std::uint16_t>& truth, const std::vector<std::uint16_t>& predicted) {
  if (truth.size() != predicted.size()) throw ConfigError("label vectors of different sizes");
  for (std::size_t i = 0; i < truth.size(); ++i) {
    ++confusion_[to_learning_class(truth[i])][to_learning_class(predicted[i])];
  }
}

std::uint64_t SegmentationScore::truth_count(int c) const {
  std::uint64_t sum = 0;
  for (int p = 0; p < kNumLearningClasses; ++p) sum += confusion_[static_cast<std::size_t>(c)][static_cast<std::size_t>(p)];
  return sum;
}

double SegmentationScore::iou(int c) const {
  // As in the SemanticKITTI API: points whose truth is ignored (0) do not count.
  const auto uc = static_cast<std::size_t>(c);
  const std::uint64_t tp = confusion_[uc][uc];
  std::uint64_t fn = 0, fp = 0;
  for (std::size_t k = 1; k < static_cast<std::size_t>(kNumLearningClasses); ++k) {
    if (k == uc) continue;
    fn += confusion_[uc][k];
    fp += confusion_[k][uc];
  }
  fn += confusion_[uc][0];
  const std::uint64_t denom = tp + fp + fn;
  return denom == 0 ? std::numeric_limits<double>::quiet_NaN() : static_cast<double>(tp) / static_cast<double>(denom);
}

double SegmentationScore::miou() const {
  double sum = 0;
  int count = 0;
  for (int c = 1; c < kNumLearningClasses; ++c) {
    if (truth_count(c) == 0) continue;
    sum += iou(c);
    ++count;
  }
  return count == 0 ? std::numeric_limits<double>::quiet_NaN() : sum / count;
}

double SegmentationScore::accuracy() const {
  std::uint64_t ok = 0, all = 0;
  for (std::size_t c = 1; c < static_cast<std::size_t>(kNumLearningClasses); ++c) {
    for (std::size_t p = 0; p < static_cast<std::size_t>(kNumLearningClasses); ++p) all += confusion_[c][p];
    ok += confusion_[c][c];
  }
  return all == 0 ? 0.0 : static_cast<double>(ok) / static_cast<double>(all);
}

nlohmann::json SegmentationScore::to_json() const {
  nlohmann::json iou = nlohmann::json::object(), points = nlohmann::json::object();
  for (int c = 1; c < kNumLearningClasses; ++c) {
    const double value = this->iou(c);
    if (std::isnan(value)) continue;
    const std::string name(learning_class_name(static_cast<std::uint8_t>(c)));
    iou[name] = value;
    points[name] = truth_count(c);
  }
  const double mean = miou();
  return {{"miou", std::isnan(mean) ? nlohmann::json() : nlohmann::json(mean)},
          {"accuracy", accuracy()},
          {"iou", iou},
          {"points", points},
          {"confusion", confusion_}};
}

}  // namespace saloam
