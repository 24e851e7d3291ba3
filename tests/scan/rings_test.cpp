// Rings from what a sensor says about its points (scan/rings.hpp) and how
// scan_rings() uses them: the ring field first, a sensor profile's laser
// elevations for scans not stored ring by ring.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "saloam/core/config.hpp"
#include "saloam/scan/rings.hpp"
#include "testing/synthetic_scans.hpp"

namespace saloam {
namespace {

constexpr int kPerLaser = testing::kVlp16PointsPerLaser;

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
  const LabelledCloud cloud = testing::shuffled_vlp16_sphere();
  FeatureConfig config;
  expect_vlp16_rings(cloud, scan_rings(cloud, config));
}

TEST(Rings, WithoutARingFieldTheProfilesLasersSortThePoints) {
  LabelledCloud cloud = testing::shuffled_vlp16_sphere();
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
