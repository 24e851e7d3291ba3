// The features' sweep times (for de-skewing) are the points' own times when
// the scan has them, else the sweep model's from the azimuth.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "saloam/core/config.hpp"
#include "saloam/odometry/features.hpp"

namespace saloam {
namespace {

/// A 16-laser scan (VLP-16: +15 to -15 deg in 2 deg steps) of a 10 m
/// sphere, 720 points per laser at 0.5 deg, turning clockwise from behind
/// the sensor (the sweep model's default), each point's laser in `ring` and
/// its time in the sweep, stored in a shuffled order (no storage-order rings).
LabelledCloud vlp16_sphere() {
  constexpr int kPerLaser = 720;
  LabelledCloud cloud;
  std::vector<std::uint16_t> ring;
  std::vector<float> time;
  for (int laser = 0; laser < 16; ++laser) {
    const double el = (15.0 - 2.0 * laser) * M_PI / 180.0;
    for (int a = 0; a < kPerLaser; ++a) {
      const double az = M_PI - (a + 0.5) * 0.5 * M_PI / 180.0;
      cloud.push_back(Eigen::Vector3d(10 * std::cos(el) * std::cos(az), 10 * std::cos(el) * std::sin(az),
                                      10 * std::sin(el)).cast<float>(),
                      0.5f);
      ring.push_back(static_cast<std::uint16_t>(15 - laser));
      time.push_back(0.1f * static_cast<float>(a) / static_cast<float>(kPerLaser));
    }
  }
  cloud.ring = ring;
  cloud.time = time;
  std::vector<std::size_t> order(cloud.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin(), order.end(), std::mt19937(3));
  LabelledCloud shuffled;
  for (const std::size_t i : order) shuffled.push_back_from(cloud, i);
  return shuffled;
}

TEST(FeatureTimes, PerPointTimesAreTheFeaturesSweepTimes) {
  LabelledCloud cloud = vlp16_sphere();
  FeatureConfig config;
  config.min_range = 1.0;
  // The cloud's own times, shifted: the sweep model (azimuth) would say otherwise.
  for (float& t : cloud.time) t -= 0.1f;
  const ScanFeatures with_times = extract_features(cloud, config, false);
  ASSERT_GT(with_times.planars.size(), 10u);
  for (std::size_t i = 0; i < with_times.planars.size(); ++i) {
    ASSERT_LE(with_times.planars.sweep_time[i], 0.0f);
    ASSERT_GE(with_times.planars.sweep_time[i], -0.1f);
  }
  cloud.time.clear();
  const ScanFeatures from_azimuth = extract_features(cloud, config, false);
  ASSERT_EQ(from_azimuth.planars.size(), with_times.planars.size());
  for (std::size_t i = 0; i < from_azimuth.planars.size(); ++i) {
    ASSERT_NEAR(from_azimuth.planars.sweep_time[i], with_times.planars.sweep_time[i] + 0.1f, 1e-4) << i;
  }
}

}  // namespace
}  // namespace saloam
