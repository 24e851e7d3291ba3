#include <cmath>

#include <gtest/gtest.h>

#include "saloam/scan/rings.hpp"
#include "saloam/sim/simulator.hpp"

namespace saloam {
namespace {

/// A 64-beam scan of the built-in urban loop without the rings in `drop`.
LabelledCloud scan_without(const std::vector<int>& drop, std::vector<int>* ring_of_point) {
  SimulationOptions options;
  options.preset = "urban-loop";
  options.first_frame = 30;
  options.end_frame = 31;
  options.show_progress = false;
  const SimulatedSequence sequence(options);
  const LabelledCloud full = sequence.render(0).cloud;
  const PointRings rings = point_rings(full, FeatureConfig{});
  EXPECT_EQ(rings.beams, 64);
  LabelledCloud out;
  for (std::size_t i = 0; i < full.size(); ++i) {
    if (std::find(drop.begin(), drop.end(), rings.ring[i]) != drop.end()) continue;
    out.push_back_from(full, i);
    ring_of_point->push_back(rings.ring[i]);
  }
  return out;
}

TEST(PointRings, RingsThatReturnedNothingKeepTheirRows) {
  for (const auto& drop : std::vector<std::vector<int>>{{0}, {0, 1}, {20}, {0, 40, 41}}) {
    std::vector<int> truth;
    const LabelledCloud cloud = scan_without(drop, &truth);
    const PointRings rings = point_rings(cloud, FeatureConfig{});
    EXPECT_EQ(rings.beams, 64);
    std::size_t right = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) right += rings.ring[i] == truth[i];
    EXPECT_EQ(right, cloud.size()) << "rings dropped: " << drop.size() << " first " << drop.front();
  }
}

TEST(PointRings, ASixteenBeamScanHasSixteenRows) {
  SimulationOptions options;
  options.preset = "urban-loop";
  options.first_frame = 30;
  options.end_frame = 31;
  options.beams = 16;
  options.show_progress = false;
  const SimulatedSequence sequence(options);
  const PointRings rings = point_rings(sequence.render(0).cloud, FeatureConfig{});
  EXPECT_EQ(rings.beams, 16);
  EXPECT_EQ(*std::max_element(rings.ring.begin(), rings.ring.end()), 15);
}

}  // namespace
}  // namespace saloam
