// A ring for every point, as a range image's rows (rings.hpp: point_rings).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "saloam/scan/rings.hpp"

namespace saloam {

namespace {

/// Median elevation [rad] of each ring (every 4th point), NaN for an empty ring.
std::vector<double> ring_elevations(const LabelledCloud& cloud, const std::vector<std::vector<std::uint32_t>>& rings) {
  std::vector<double> out;
  std::vector<double> e;
  for (const auto& ring : rings) {
    e.clear();
    for (std::size_t k = 0; k < ring.size(); k += 4) {
      const Eigen::Vector3f& p = cloud.points[ring[k]];
      e.push_back(std::atan2(static_cast<double>(p.z()), std::hypot(static_cast<double>(p.x()), static_cast<double>(p.y()))));
    }
    if (e.empty()) {
      out.push_back(std::nan(""));
      continue;
    }
    std::nth_element(e.begin(), e.begin() + static_cast<std::ptrdiff_t>(e.size() / 2), e.end());
    out.push_back(e[e.size() / 2]);
  }
  return out;
}

/// The median of the gaps near gap k (up to four on each side, k itself
/// left out): the local ring spacing (the HDL-64E's two blocks differ).
double local_spacing(const std::vector<double>& gaps, std::size_t k) {
  std::vector<double> near;
  for (std::size_t j = k >= 4 ? k - 4 : 0; j < std::min(gaps.size(), k + 5); ++j)
    if (j != k && std::isfinite(gaps[j]) && gaps[j] > 0) near.push_back(gaps[j]);
  if (near.empty()) return std::nan("");
  std::nth_element(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(near.size() / 2), near.end());
  return near[near.size() / 2];
}

/// Row of each found ring in an image of `rows` rows (rows >= found rings):
/// a ring that returned nothing (the sky above a top beam, a lost beam)
/// leaves a gap; a gap of about n + 1 local ring spacings gets n empty rows
/// (widest gaps first), and what is still missing goes above the top ring.
std::vector<int> ring_rows(const std::vector<double>& elevation, int rows) {
  const int found = static_cast<int>(elevation.size());
  std::vector<double> gaps, spacing;  // gap k lies between rings k and k + 1
  for (int k = 1; k < found; ++k) gaps.push_back(elevation[k - 1] - elevation[k]);
  for (std::size_t k = 0; k < gaps.size(); ++k) spacing.push_back(local_spacing(gaps, k));
  std::vector<int> extra(static_cast<std::size_t>(found), 0);  // empty rows inserted above ring k
  int missing = rows - found;
  for (; missing > 0; --missing) {
    std::size_t widest = gaps.size();
    double ratio = 0;
    for (std::size_t k = 0; k < gaps.size(); ++k) {
      const double rings_in_gap = gaps[k] / spacing[k];
      const double r = rings_in_gap / (1 + extra[k + 1]);
      if (std::isfinite(r) && std::lround(rings_in_gap) - 1 > extra[k + 1] && r > ratio) {
        ratio = r;
        widest = k;
      }
    }
    if (widest == gaps.size()) break;
    ++extra[widest + 1];
  }
  std::vector<int> row(static_cast<std::size_t>(found));
  int next = std::max(missing, 0);  // what is still missing goes above the top ring
  for (int k = 0; k < found; ++k) {
    next += extra[static_cast<std::size_t>(k)];
    row[static_cast<std::size_t>(k)] = next++;
  }
  return row;
}

/// The sensor's beam count: config.num_beams, else the smallest common count
/// (16, 32, 64, 128) that holds the rings found.
int sensor_beams(int found, const FeatureConfig& config) {
  if (config.num_beams > 0) return std::max(config.num_beams, found);
  for (int beams : {16, 32, 64, 128})
    if (found <= beams) return beams;
  return found;
}

}  // namespace

PointRings point_rings(const LabelledCloud& cloud, const FeatureConfig& config) {
  const auto rings = scan_rings(cloud, config);
  const int found = static_cast<int>(rings.size());
  PointRings out{std::vector<std::int16_t>(cloud.size(), -1), sensor_beams(found, config)};
  const std::vector<int> row = found == out.beams ? std::vector<int>() : ring_rows(ring_elevations(cloud, rings), out.beams);
  for (std::size_t r = 0; r < rings.size(); ++r)
    for (const std::uint32_t i : rings[r]) out.ring[i] = static_cast<std::int16_t>(row.empty() ? static_cast<int>(r) : row[r]);
  return out;
}

}  // namespace saloam
