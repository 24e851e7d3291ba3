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
#include "testing/synthetic_scans.hpp"

namespace saloam {
namespace {

TEST(FeatureTimes, PerPointTimesAreTheFeaturesSweepTimes) {
  LabelledCloud cloud = testing::shuffled_vlp16_sphere();
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
