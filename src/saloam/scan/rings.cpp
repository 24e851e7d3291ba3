#include "saloam/scan/rings.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace saloam {
namespace {

double elevation_deg(const Eigen::Vector3f& p) {
  return std::atan2(static_cast<double>(p.z()), std::hypot(static_cast<double>(p.x()), static_cast<double>(p.y()))) *
         180.0 / M_PI;
}

/// Sorts every ring's indices by sweep time (stable: ties keep storage order).
/// Drivers and the simulator store a ring in firing order already: then the
/// check is all it costs.
void order_by_time(RingIndices& rings, const std::vector<float>& times) {
  const auto earlier = [&](std::uint32_t a, std::uint32_t b) { return times[a] < times[b]; };
  for (auto& ring : rings)
    if (!std::is_sorted(ring.begin(), ring.end(), earlier)) std::stable_sort(ring.begin(), ring.end(), earlier);
}

/// Mean elevation [deg] of a ring's points, from every 8th point of a ring
/// of more than 64 (the elevation only orders rings, which lie a few tenths
/// of a degree apart or more; a ring's points agree far closer than that).
double mean_elevation_deg(const LabelledCloud& cloud, const std::vector<std::uint32_t>& ring) {
  const std::size_t step = ring.size() > 64 ? 8 : 1;
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < ring.size(); k += step, ++n) sum += elevation_deg(cloud.points[ring[k]]);
  return sum / static_cast<double>(n);
}

}  // namespace

RingIndices rings_from_ring_field(const LabelledCloud& cloud, const std::vector<float>& times) {
  // Rings in the order their values first occur; bucket_of[value] + 1 is the
  // ring of a value (0: not seen yet).
  std::vector<std::uint32_t> bucket_of(std::size_t{*std::max_element(cloud.ring.begin(), cloud.ring.end())} + 1, 0);
  RingIndices rings;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (times[i] < 0.0f) continue;
    std::uint32_t& bucket = bucket_of[cloud.ring[i]];
    if (bucket == 0) {
      rings.emplace_back().reserve(cloud.size() / 32);
      bucket = static_cast<std::uint32_t>(rings.size());
    }
    rings[bucket - 1].push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<double> elevation(rings.size());
  for (std::size_t r = 0; r < rings.size(); ++r) elevation[r] = mean_elevation_deg(cloud, rings[r]);
  std::vector<std::size_t> order(rings.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return elevation[a] > elevation[b]; });
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
