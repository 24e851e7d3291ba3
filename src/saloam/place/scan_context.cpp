#include "saloam/place/scan_context.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

namespace saloam {

ScanContext make_scan_context(std::span<const Eigen::Vector3f> points, const ScanContextConfig& config) {
  constexpr float kNoPoint = -1000.0F;
  Eigen::MatrixXf grid = Eigen::MatrixXf::Constant(config.num_rings, config.num_sectors, kNoPoint);
  const double ring_width = config.max_range / config.num_rings;
  const double sector_width = 2.0 * std::numbers::pi / config.num_sectors;
  const double max_range_squared = config.max_range * config.max_range;
  for (const auto& p : points) {
    // Range by sqrt (std::hypot's overflow care costs several times more).
    const double x = p.x(), y = p.y();
    const double range_squared = x * x + y * y;
    if (!(range_squared < max_range_squared)) continue;
    const double range = std::sqrt(range_squared);
    double azimuth = std::atan2(y, x);
    if (azimuth < 0) azimuth += 2.0 * std::numbers::pi;
    const int ring = std::min(static_cast<int>(range / ring_width), config.num_rings - 1);
    const int sector = std::min(static_cast<int>(azimuth / sector_width), config.num_sectors - 1);
    float& cell = grid(ring, sector);
    cell = std::max(cell, p.z() + static_cast<float>(config.lidar_height));
  }
  return scan_context_from_descriptor((grid.array() == kNoPoint).select(0.0F, grid));
}

ScanContext scan_context_from_descriptor(Eigen::MatrixXf descriptor) {
  ScanContext sc;
  sc.descriptor = std::move(descriptor);
  sc.ring_key = sc.descriptor.rowwise().mean();
  sc.unit_columns = sc.descriptor;
  for (Eigen::Index c = 0; c < sc.unit_columns.cols(); ++c) {
    const float norm = sc.unit_columns.col(c).norm();
    if (norm > 0) sc.unit_columns.col(c) /= norm;
  }
  return sc;
}

ScanContextMatch scan_context_distance(const ScanContext& query, const ScanContext& candidate) {
  if (query.descriptor.rows() != candidate.descriptor.rows() || query.descriptor.cols() != candidate.descriptor.cols())
    throw std::invalid_argument("scan_context_distance: descriptors of different sizes");
  const int sectors = static_cast<int>(query.descriptor.cols());
  // All column cosines at once: gram(a, b) = cos(query column a, candidate column b).
  const Eigen::MatrixXf gram = query.unit_columns.transpose() * candidate.unit_columns;
  std::vector<char> query_full(static_cast<std::size_t>(sectors)), candidate_full(static_cast<std::size_t>(sectors));
  for (int c = 0; c < sectors; ++c) {
    query_full[c] = query.unit_columns.col(c).squaredNorm() > 0;
    candidate_full[c] = candidate.unit_columns.col(c).squaredNorm() > 0;
  }
  ScanContextMatch best;
  best.distance = std::numeric_limits<double>::infinity();
  for (int shift = 0; shift < sectors; ++shift) {
    double similarity = 0;
    int columns = 0;
    for (int c = 0; c < sectors; ++c) {
      const int d = (c + shift) % sectors;  // candidate column shifted onto query column c
      if (!query_full[c] || !candidate_full[d]) continue;
      similarity += gram(c, d);
      ++columns;
    }
    const double distance = columns > 0 ? 1.0 - similarity / columns : 1.0;
    if (distance < best.distance) best = {distance, shift};
  }
  return best;
}

std::vector<std::size_t> ring_key_candidates(const ScanContext& query, std::span<const ScanContext> database,
                                             std::size_t searchable, std::size_t count) {
  searchable = std::min(searchable, database.size());
  std::vector<std::pair<float, std::size_t>> distances(searchable);
  for (std::size_t i = 0; i < searchable; ++i)
    distances[i] = {(database[i].ring_key - query.ring_key).squaredNorm(), i};
  count = std::min(count, searchable);
  std::partial_sort(distances.begin(), distances.begin() + static_cast<std::ptrdiff_t>(count), distances.end());
  std::vector<std::size_t> result(count);
  for (std::size_t i = 0; i < count; ++i) result[i] = distances[i].second;
  return result;
}

}  // namespace saloam
