#include "saloam/odometry/rings.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

namespace saloam {
namespace {

double elevation_deg(const Eigen::Vector3f& p) {
  return std::atan2(static_cast<double>(p.z()), std::hypot(static_cast<double>(p.x()), static_cast<double>(p.y()))) *
         180.0 / M_PI;
}

/// Sorts every ring's indices by sweep time (stable: ties keep storage order).
void order_by_time(RingIndices& rings, const std::vector<float>& times) {
  for (auto& ring : rings) {
    std::stable_sort(ring.begin(), ring.end(), [&](std::uint32_t a, std::uint32_t b) { return times[a] < times[b]; });
  }
}

}  // namespace

RingIndices rings_from_ring_field(const LabelledCloud& cloud, const std::vector<float>& times) {
  std::map<std::uint16_t, std::size_t> bucket_of;
  RingIndices rings;
  std::vector<double> elevation_sum;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (times[i] < 0.0f) continue;
    const auto [it, added] = bucket_of.try_emplace(cloud.ring[i], rings.size());
    if (added) {
      rings.emplace_back();
      elevation_sum.push_back(0.0);
    }
    rings[it->second].push_back(static_cast<std::uint32_t>(i));
    elevation_sum[it->second] += elevation_deg(cloud.points[i]);
  }
  std::vector<std::size_t> order(rings.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto mean = [&](std::size_t r) { return elevation_sum[r] / static_cast<double>(rings[r].size()); };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return mean(a) > mean(b); });
  RingIndices sorted;
  sorted.reserve(rings.size());
  for (const std::size_t r : order) sorted.push_back(std::move(rings[r]));
  order_by_time(sorted, times);
  return sorted;
}

RingIndices rings_from_laser_elevations(const LabelledCloud& cloud, const std::vector<float>& times,
                                        const std::vector<double>& elevation_deg_top_first) {
  const auto& lasers = elevation_deg_top_first;
  RingIndices rings(lasers.size());
  if (lasers.empty()) return rings;
  const double half_top = lasers.size() > 1 ? 0.5 * (lasers[0] - lasers[1]) : 1.0;
  const double half_bottom = lasers.size() > 1 ? 0.5 * (lasers[lasers.size() - 2] - lasers.back()) : 1.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (times[i] < 0.0f) continue;
    const double e = elevation_deg(cloud.points[i]);
    if (e > lasers.front() + half_top || e < lasers.back() - half_bottom) continue;
    // First laser at or below e (the list decreases), then the nearer of it and the one above.
    const auto below = std::lower_bound(lasers.begin(), lasers.end(), e, std::greater<>());
    std::size_t r = static_cast<std::size_t>(below - lasers.begin());
    if (r == lasers.size()) {
      r = lasers.size() - 1;
    } else if (r > 0 && lasers[r - 1] - e < e - lasers[r]) {
      r = r - 1;
    }
    rings[r].push_back(static_cast<std::uint32_t>(i));
  }
  order_by_time(rings, times);
  return rings;
}

}  // namespace saloam
