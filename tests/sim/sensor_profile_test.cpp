// Sensor profiles (core/sensor_profile.hpp): the shipped files, their checks,
// and the simulator rendering them (sim/lidar.hpp): lasers, mount height,
// ring and time per point.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "saloam/core/error.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/core/sensor_profile.hpp"
#include "saloam/sim/lidar.hpp"
#include "saloam/sim/simulator.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

std::vector<SensorProfile> shipped() { return load_sensor_profiles(testing::source_dir() / "config" / "sensors"); }

const SensorProfile& named(const std::vector<SensorProfile>& all, const std::string& name) {
  const auto it = std::find_if(all.begin(), all.end(), [&](const SensorProfile& p) { return p.name == name; });
  if (it == all.end()) throw std::runtime_error("no profile " + name);
  return *it;
}

TEST(SensorProfiles, TheShippedOnesLoad) {
  const auto all = shipped();
  std::vector<std::pair<std::string, int>> found;
  for (const auto& p : all) found.emplace_back(p.name, p.beams());
  EXPECT_EQ(found, (std::vector<std::pair<std::string, int>>{
                       {"hdl32e", 32}, {"hdl64e", 64}, {"os1-128", 128}, {"os1-64", 64}, {"vlp16", 16}}));
  const auto& vlp = named(all, "vlp16");
  EXPECT_DOUBLE_EQ(vlp.elevation_deg.front(), 15.0);
  EXPECT_DOUBLE_EQ(vlp.elevation_deg.back(), -15.0);
  EXPECT_DOUBLE_EQ(vlp.simulation.mount_height, 1.0);
  EXPECT_FALSE(vlp.simulation.kitti_ego_body);
  // The simulator's default sensor has the hdl64e profile's lasers.
  const auto& hdl = named(all, "hdl64e");
  const LidarModel kitti = LidarModel::hdl64e(64);
  ASSERT_EQ(hdl.elevation_deg.size(), kitti.elevation_deg.size());
  for (std::size_t i = 0; i < kitti.elevation_deg.size(); ++i) EXPECT_NEAR(hdl.elevation_deg[i], kitti.elevation_deg[i], 1e-4) << i;
  EXPECT_EQ(hdl.simulation.azimuth_steps, kitti.azimuth_steps);
}

TEST(SensorProfiles, BadFilesNameTheProblem) {
  const auto error_of = [](const std::string& yaml) {
    return testing::input_error_of([&] { (void)parse_sensor_profile(yaml, "bad.yaml"); });
  };
  const std::string good =
      "name: x\nmodel: X\nelevation_deg: [1, 0, -1]\nmin_range: 0.5\nmax_range: 50\nsweep_duration: 0.1\n"
      "sweep_clockwise: true\nsweep_start_azimuth_deg: 180\nsimulation: {azimuth_steps: 900, mount_height: 1.2, "
      "ego_body: none, range_noise: 0.02}\n";
  EXPECT_EQ(parse_sensor_profile(good, "good.yaml").beams(), 3);
  EXPECT_EQ(error_of("name: x\n"), "bad.yaml: sensor profile without 'model'");
  std::string unsorted = good;
  unsorted.replace(unsorted.find("[1, 0, -1]"), 10, "[1, 2, -1]");
  EXPECT_EQ(error_of(unsorted), "bad.yaml: elevation_deg[1] = 2 does not lie below 1 (top laser first)");
  std::string body = good;
  body.replace(body.find("ego_body: none"), 14, "ego_body: bus");
  EXPECT_EQ(error_of(body), "bad.yaml: simulation.ego_body 'bus': kitti or none");
  EXPECT_NE(error_of("[").find("bad.yaml: not valid YAML"), std::string::npos);
  EXPECT_EQ(error_of(good + "max_range: 80\n"), "bad.yaml: 'max_range' is given twice (lines 5 and 10): give each key once");
  EXPECT_EQ(error_of(good + "---\n" + good), "bad.yaml: holds 2 YAML documents (separated by '---'); a sensor profile is one");
}

TEST(SensorProfiles, AppliedToTheOdometrysSettings) {
  const auto all = shipped();
  const auto& vlp = named(all, "vlp16");
  FeatureConfig features;
  apply_sensor_profile(vlp, features);
  EXPECT_EQ(features.num_beams, 16);
  EXPECT_EQ(features.beam_elevations_deg, vlp.elevation_deg);
  EXPECT_DOUBLE_EQ(features.max_range, 100.0);  // the sensor's, below the configured 120
  EXPECT_DOUBLE_EQ(features.min_range, FeatureConfig{}.min_range);  // the configured one keeps the car out
}

/// Frame 0 of a short simulated route with `sensor` (coarse azimuth: cheap).
SimulatedFrame first_frame(const SensorProfile& sensor) {
  SimulationOptions options;
  options.preset = "straight";
  options.end_frame = 2;
  options.sensor = sensor;
  options.azimuth_steps = 600;
  options.show_progress = false;
  return SimulatedSequence(options).render(0);
}

TEST(SensorProfiles, TheSimulatorRendersAVlp16FromItsLowerMount) {
  const SimulatedFrame frame = first_frame(named(shipped(), "vlp16"));
  const LabelledCloud& cloud = frame.cloud;
  ASSERT_TRUE(cloud.has_rings() && cloud.has_times());
  EXPECT_EQ(*std::max_element(cloud.ring.begin(), cloud.ring.end()), 15);
  double top = -90, bottom = 90;
  std::vector<double> road_z;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto& p = cloud.points[i];
    const double horizontal = std::hypot(p.x(), p.y());
    const double e = std::atan2(p.z(), horizontal) * 180.0 / M_PI;
    top = std::max(top, e);
    bottom = std::min(bottom, e);
    if (cloud.label[i] == cls::kRoad && horizontal < 8.0) road_z.push_back(p.z());
    ASSERT_GE(cloud.time[i], 0.0f);
    ASSERT_LE(cloud.time[i], 0.1f);
  }
  EXPECT_NEAR(top, 15.0, 0.5);  // range noise moves points along the ray only
  EXPECT_NEAR(bottom, -15.0, 0.5);
  ASSERT_GT(road_z.size(), 50u);
  std::nth_element(road_z.begin(), road_z.begin() + static_cast<std::ptrdiff_t>(road_z.size() / 2), road_z.end());
  EXPECT_NEAR(road_z[road_z.size() / 2], -1.0, 0.15);  // the road 1.0 m below the sensor, not KITTI's 1.73 m
}

TEST(SensorProfiles, ProfilesAndBeamsAreExclusive) {
  SimulationOptions options;
  options.preset = "straight";
  options.sensor = named(shipped(), "vlp16");
  options.beams = 16;
  EXPECT_THROW((void)SimulatedSequence(options), ConfigError);
}

}  // namespace
}  // namespace saloam
