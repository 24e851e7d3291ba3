#include "saloam/sim/class_shares.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "saloam/core/progress.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/sim/simulator.hpp"

namespace saloam {
namespace {

// semantic-kitti.yaml, `content` (ratios to all points of the annotated sequences).
constexpr std::array<ReferenceShare, 8> kSemanticKitti{{
    {cls::kVegetation, 0.26681502148037506},
    {cls::kRoad, 0.1987493871255525},
    {cls::kSidewalk, 0.14392298360372},
    {cls::kBuilding, 0.1326861944777486},
    {cls::kTerrain, 0.07814222006271769},
    {cls::kFence, 0.0723592229456223},
    {cls::kCar, 0.040818519255974316},
    {cls::kParking, 0.014717169549888214},
}};

bool is_reference(std::uint16_t label) {
  return std::any_of(kSemanticKitti.begin(), kSemanticKitti.end(), [&](const ReferenceShare& r) { return r.label == label; });
}

}  // namespace

std::span<const ReferenceShare> semantic_kitti_shares() { return kSemanticKitti; }

void ClassShares::add(std::span<const std::uint16_t> labels) {
  for (const std::uint16_t l : labels) ++counts_[std::min<std::size_t>(l, kLabels - 1)];
  total_ += labels.size();
}

void ClassShares::merge(const ClassShares& other) {
  for (std::size_t i = 0; i < kLabels; ++i) counts_[i] += other.counts_[i];
  total_ += other.total_;
}

std::uint64_t ClassShares::count(std::uint16_t label) const { return counts_[std::min<std::size_t>(label, kLabels - 1)]; }

double ClassShares::share(std::uint16_t label) const {
  return total_ == 0 ? 0.0 : static_cast<double>(count(label)) / static_cast<double>(total_);
}

std::string format_class_shares(const ClassShares& shares) {
  std::string out = fmt::format("{:<14} {:>8} {:>14} {:>9}\n", "class", "share %", "SemanticKITTI %", "relative");
  for (const ReferenceShare& r : kSemanticKitti) {
    const double s = shares.share(r.label);
    const double rel = ClassShares::relative_error(s, r.share);
    out += fmt::format("{:<14} {:8.2f} {:14.2f} {:+8.0f} %{}\n", class_name(r.label), 100.0 * s, 100.0 * r.share,
                       100.0 * rel, std::abs(rel) <= kShareTolerance ? "" : "  (outside +-30 %)");
  }
  for (std::uint16_t label = 0; label < 260; ++label) {
    if (is_reference(label) || shares.share(label) < 0.001) continue;
    out += fmt::format("{:<14} {:8.2f}\n", class_name(label), 100.0 * shares.share(label));
  }
  out += fmt::format("({} points)\n", shares.total());
  return out;
}

ClassShares measure_class_shares(const SimulatedSequence& sequence, bool show_progress) {
  ClassShares shares;
  ProgressBar progress(sequence.size(), "class shares", show_progress);
  for (std::size_t k = 0; k < sequence.size(); ++k) {
    const SimulatedFrame frame = sequence.render(k);
    shares.add(frame.gt_labels.empty() ? std::span<const std::uint16_t>(frame.cloud.label)
                                       : std::span<const std::uint16_t>(frame.gt_labels));
    progress.advance();
  }
  progress.finish();
  return shares;
}

}  // namespace saloam
