// `--sensor auto` (sources/sensor_guess.hpp): each shipped profile, rendered
// by the simulator, is recognised from one scan, with its ring field and
// without (storage order, then elevations alone); the HDL-64E's 32 and 16
// laser subsets are still an HDL-64E, whose runs take the lasers kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "saloam/core/error.hpp"
#include "saloam/sim/lidar.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sources/lasers.hpp"
#include "saloam/sources/sensor_guess.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

const std::vector<SensorProfile>& shipped() {
  static const auto all = load_sensor_profiles(testing::source_dir() / "config" / "sensors");
  return all;
}

LabelledCloud first_scan(const std::optional<SensorProfile>& sensor, int beams = 64) {
  SimulationOptions options;
  options.preset = "straight";
  options.end_frame = 1;
  options.sensor = sensor;
  options.beams = beams;
  options.azimuth_steps = 900;
  options.show_progress = false;
  return SimulatedSequence(options).render(0).cloud;
}

std::string guessed(const LabelledCloud& cloud) { return shipped()[guess_sensor(cloud, shipped()).profile].name; }

TEST(SensorGuess, EveryShippedSensorIsRecognisedFromOneScan) {
  for (const auto& profile : shipped()) {
    SCOPED_TRACE(profile.name);
    LabelledCloud cloud = first_scan(profile);
    const FoundLasers with_field = find_lasers(cloud);
    EXPECT_EQ(with_field.method, BeamMethod::kRingField);
    EXPECT_LE(with_field.count(), static_cast<std::size_t>(profile.beams()));
    EXPECT_GE(with_field.count(), static_cast<std::size_t>(profile.beams()) * 9 / 10);  // a laser may see only sky
    EXPECT_EQ(guessed(cloud), profile.name);
    cloud.ring.clear();  // stored laser after laser, as a .bin file keeps it
    EXPECT_EQ(find_lasers(cloud).method, BeamMethod::kAzimuthWraps);
    EXPECT_EQ(guessed(cloud), profile.name);
  }
}

TEST(SensorGuess, ThinnedHdl64eIsStillAnHdl64eAndShuffledScansFallBackOnElevations) {
  for (const int beams : {32, 16}) {
    SCOPED_TRACE(beams);
    const LabelledCloud cloud = first_scan(std::nullopt, beams);
    EXPECT_EQ(guessed(cloud), "hdl64e");
    // A run takes the lasers the scans keep: the simulator's every 2nd or 4th.
    const auto hdl = std::find_if(shipped().begin(), shipped().end(), [](const auto& p) { return p.name == "hdl64e"; });
    const auto subset = laser_subset(*hdl, find_lasers(cloud));
    ASSERT_TRUE(subset.has_value());
    const auto expected = LidarModel::hdl64e(beams).elevation_deg;
    ASSERT_EQ(subset->elevation_deg.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(subset->elevation_deg[i], expected[i], 1e-4) << i;
  }
  // Every laser, or most of them: the profile as it is.
  for (const auto& profile : shipped()) EXPECT_FALSE(laser_subset(profile, find_lasers(first_scan(profile))).has_value());
  // Points in no order: lasers from the elevation clusters alone.
  const auto vlp = std::find_if(shipped().begin(), shipped().end(), [](const auto& p) { return p.name == "vlp16"; });
  LabelledCloud cloud = first_scan(*vlp);
  std::vector<std::size_t> order(cloud.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), std::mt19937(1));
  LabelledCloud shuffled;
  for (const std::size_t i : order) shuffled.push_back(cloud.points[i], cloud.remission[i]);
  const SensorGuess guess = guess_sensor(shuffled, shipped());
  EXPECT_EQ(guess.lasers.method, BeamMethod::kElevation);
  EXPECT_EQ(shipped()[guess.profile].name, "vlp16");
  EXPECT_NE(guess.found().find("lasers (elevation angles; no ring field) from +15."), std::string::npos) << guess.found();
  EXPECT_THROW((void)guess_sensor(shuffled, {}), ConfigError);
}

}  // namespace
}  // namespace saloam
