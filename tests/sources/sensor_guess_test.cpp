// `--sensor auto` (sources/sensor_guess.hpp): each shipped profile, rendered
// by the simulator, is recognised from one scan, with its ring field and
// without (storage order, then elevations alone); the HDL-64E's 32 and 16
// laser subsets are still an HDL-64E, whose runs take the lasers kept; scans
// in a turned frame are recognised by their lasers' spin axis.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
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

// Scans handed over in a turned frame (a robot's base link; issue #50): the
// lasers' elevations are read about their own spin axis, so each sensor is
// still recognised, and the axis found is the sensor's z turned.
TEST(SensorGuess, ScansInATurnedFrameAreRecognisedByTheirSpinAxis) {
  for (const auto& profile : shipped()) {
    SCOPED_TRACE(profile.name);
    LabelledCloud cloud = first_scan(profile);
    const Eigen::Matrix3d turn = rotation_from_rpy_deg(Eigen::Vector3d(5, 20, 30));
    for (auto& p : cloud.points) p = (turn.cast<float>() * p).eval();
    for (const bool ring_field : {true, false}) {
      if (!ring_field) cloud.ring.clear();
      const FoundLasers lasers = find_lasers(cloud);
      // The sweep's motion bends the lasers' cones a little: measured 0.56 and
      // 0.76 deg with the 32 and 16 lasers of a moving VLP-16 / HDL-32E.
      EXPECT_LT(std::acos(std::min(1.0, lasers.spin_axis.dot(turn.col(2)))) * 180.0 / M_PI, 1.2);
      EXPECT_EQ(guessed(cloud), profile.name);
    }
  }
  // A level scan keeps the cloud's z.
  EXPECT_EQ(find_lasers(first_scan(std::nullopt)).spin_axis, Eigen::Vector3d::UnitZ());
}

}  // namespace
}  // namespace saloam
