#include "testing/synthetic_scans.hpp"

#include <cmath>
#include <numeric>
#include <random>
#include <vector>

namespace saloam::testing {

LabelledCloud shuffled_vlp16_sphere() {
  LabelledCloud cloud;
  std::vector<std::uint16_t> ring;
  std::vector<float> time;
  for (int laser = 0; laser < 16; ++laser) {
    const double el = (15.0 - 2.0 * laser) * M_PI / 180.0;
    for (int a = 0; a < kVlp16PointsPerLaser; ++a) {
      const double az = M_PI - (a + 0.5) * 0.5 * M_PI / 180.0;  // clockwise from behind
      cloud.push_back(Eigen::Vector3d(10 * std::cos(el) * std::cos(az), 10 * std::cos(el) * std::sin(az),
                                      10 * std::sin(el)).cast<float>(),
                      0.5f);
      ring.push_back(static_cast<std::uint16_t>(15 - laser));
      time.push_back(0.1f * static_cast<float>(a) / static_cast<float>(kVlp16PointsPerLaser));
    }
  }
  cloud.ring = ring;  // after the points: push_back() clears the per-point fields
  cloud.time = time;
  std::vector<std::size_t> order(cloud.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin(), order.end(), std::mt19937(3));
  LabelledCloud shuffled;
  for (const std::size_t i : order) shuffled.push_back_from(cloud, i);
  return shuffled;
}

}  // namespace saloam::testing
