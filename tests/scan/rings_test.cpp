// Rings from what a sensor says about its points (scan/rings.hpp) and how
// scan_rings() uses them: the ring field first, a sensor profile's laser
// elevations for scans not stored ring by ring.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "saloam/core/config.hpp"
#include "saloam/scan/rings.hpp"

namespace saloam {
namespace {

/// A 16-laser scan (VLP-16: +15 to -15 deg in 2 deg steps) of a 10 m
/// sphere, 720 points per laser at 0.5 deg (half a step off the seam behind
/// the sensor), stored in a shuffled order (no
/// storage-order rings), with each point's laser in `ring` numbered from the
/// BOTTOM (as the Velodyne driver does) and its time in the sweep.
constexpr int kPerLaser = 720;

LabelledCloud shuffled_vlp16() {
  LabelledCloud cloud;
  std::vector<std::uint16_t> ring;
  std::vector<float> time;
  for (int laser = 0; laser < 16; ++laser) {
    const double el = (15.0 - 2.0 * laser) * M_PI / 180.0;
    for (int a = 0; a < kPerLaser; ++a) {
      const double az = M_PI - (a + 0.5) * 0.5 * M_PI / 180.0;  // clockwise from behind
      cloud.push_back(Eigen::Vector3d(10 * std::cos(el) * std::cos(az), 10 * std::cos(el) * std::sin(az),
                                      10 * std::sin(el)).cast<float>(),
                      0.5f);
      ring.push_back(static_cast<std::uint16_t>(15 - laser));
      time.push_back(0.1f * static_cast<float>(a) / static_cast<float>(kPerLaser));
    }
  }
  std::vector<std::size_t> order(cloud.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), std::mt19937(3));
  LabelledCloud shuffled;
  for (const std::size_t i : order) shuffled.push_back(cloud.points[i], cloud.remission[i]);
  for (const std::size_t i : order) shuffled.ring.push_back(ring[i]);
  for (const std::size_t i : order) shuffled.time.push_back(time[i]);
  return shuffled;
}

double elevation_of(const Eigen::Vector3f& p) { return std::atan2(p.z(), std::hypot(p.x(), p.y())) * 180.0 / M_PI; }

/// Every ring holds the 720 points of one laser, top laser first, in sweep order.
void expect_vlp16_rings(const LabelledCloud& cloud, const std::vector<std::vector<std::uint32_t>>& rings) {
  ASSERT_EQ(rings.size(), 16u);
  for (std::size_t r = 0; r < rings.size(); ++r) {
    ASSERT_EQ(rings[r].size(), static_cast<std::size_t>(kPerLaser)) << r;
    for (std::size_t k = 0; k < rings[r].size(); ++k) {
      const auto& p = cloud.points[rings[r][k]];
      ASSERT_NEAR(elevation_of(p), 15.0 - 2.0 * static_cast<double>(r), 1e-3) << r;
      if (k > 0) {
        ASSERT_LT(cloud.time[rings[r][k - 1]], cloud.time[rings[r][k]]) << r << " " << k;
      }
    }
  }
}

TEST(Rings, TheRingFieldComesFirstAndIsOrderedTopDown) {
  const LabelledCloud cloud = shuffled_vlp16();
  FeatureConfig config;
  expect_vlp16_rings(cloud, scan_rings(cloud, config));
}

TEST(Rings, WithoutARingFieldTheProfilesLasersSortThePoints) {
  LabelledCloud cloud = shuffled_vlp16();
  cloud.ring.clear();
  FeatureConfig config;
  for (int laser = 0; laser < 16; ++laser) config.beam_elevations_deg.push_back(15.0 - 2.0 * laser);
  expect_vlp16_rings(cloud, scan_rings(cloud, config));
  // A point between two lasers goes to the nearer; far beyond the top or bottom one, to none.
  LabelledCloud odd;
  for (const double e : {14.2, 13.8, 15.9, 17.5, -15.9, -20.0}) {
    const double el = e * M_PI / 180.0;
    odd.push_back(Eigen::Vector3d(10 * std::cos(el), 0.0, 10 * std::sin(el)).cast<float>(), 0.5f);
  }
  const std::vector<float> times(odd.size(), 0.0f);
  const auto rings = rings_from_laser_elevations(odd, times, config.beam_elevations_deg);
  EXPECT_EQ(rings[0], (std::vector<std::uint32_t>{0, 2}));  // 14.2 and 15.9 (within half a spacing above +15)
  EXPECT_EQ(rings[1], (std::vector<std::uint32_t>{1}));     // 13.8
  EXPECT_EQ(rings[15], (std::vector<std::uint32_t>{4}));    // -15.9
  std::size_t kept = 0;
  for (const auto& r : rings) kept += r.size();
  EXPECT_EQ(kept, 4u);  // 17.5 and -20 are outside
}

}  // namespace
}  // namespace saloam
