#include "saloam/sources/sequence_summary.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

namespace saloam {

namespace {

/// Laser-after-laser storage: the number of revolutions the azimuth makes
/// from the first point to the last (each laser sweeps once around), or
/// nullopt when the points are not stored that way.
std::optional<std::size_t> azimuth_revolutions(const LabelledCloud& cloud) {
  if (cloud.size() < 200) return std::nullopt;
  std::size_t forward = 0, backward = 0, wraps_up = 0, wraps_down = 0;
  double previous = std::atan2(cloud.points[0].y(), cloud.points[0].x());
  for (std::size_t i = 1; i < cloud.size(); ++i) {
    const double azimuth = std::atan2(cloud.points[i].y(), cloud.points[i].x());
    const double step = azimuth - previous;
    previous = azimuth;
    if (step > std::numbers::pi) ++wraps_up;
    else if (step < -std::numbers::pi) ++wraps_down;
    else if (step > 0.0) ++forward;
    else if (step < 0.0) ++backward;
  }
  const std::size_t steps = forward + backward;
  const std::size_t wraps = forward > backward ? wraps_down : wraps_up;  // against the turning direction
  const bool one_way = steps > 0 && 10 * std::max(forward, backward) > 9 * steps;
  if (!one_way || wraps == 0 || cloud.size() / wraps < 100) return std::nullopt;
  // The unwrapped azimuth turns by 2 pi per wrap plus the way from the first
  // point to the last: a whole number of revolutions, one per laser.
  const double first = std::atan2(cloud.points.front().y(), cloud.points.front().x());
  const double rest = (forward > backward ? 1.0 : -1.0) * (previous - first);
  const double turns = static_cast<double>(wraps) + rest / (2.0 * std::numbers::pi);
  return static_cast<std::size_t>(std::max(1.0, std::round(turns)));
}

std::size_t elevation_clusters(const LabelledCloud& cloud) {
  std::vector<double> elevation;
  elevation.reserve(cloud.size());
  for (const auto& p : cloud.points) {
    const double horizontal = std::hypot(p.x(), p.y());
    if (horizontal > 2.0) elevation.push_back(std::atan2(p.z(), horizontal) * 180.0 / std::numbers::pi);
  }
  std::sort(elevation.begin(), elevation.end());
  const std::size_t min_points = std::max<std::size_t>(1, elevation.size() / 1000);
  constexpr double kGap = 0.15;  // [deg]
  std::size_t beams = 0, members = 0;
  for (std::size_t i = 0; i < elevation.size(); ++i) {
    if (i > 0 && elevation[i] - elevation[i - 1] > kGap) {
      beams += members >= min_points;
      members = 0;
    }
    ++members;
  }
  return beams + (members > 0 && members >= min_points);
}

}  // namespace

BeamEstimate estimate_beams(const LabelledCloud& cloud) {
  if (cloud.has_rings()) {
    const std::set<std::uint16_t> rings(cloud.ring.begin(), cloud.ring.end());
    return {rings.size(), BeamMethod::kRingField};
  }
  if (const auto turns = azimuth_revolutions(cloud)) return {*turns, BeamMethod::kAzimuthWraps};
  return {elevation_clusters(cloud), BeamMethod::kElevation};
}

SequenceSummary summarize(FrameSource& source, std::size_t scans_to_read) {
  const SourceInfo& info = source.info();
  SequenceSummary s;
  s.format = info.format;
  s.frames = source.size();
  const auto& t = info.times;
  if (!t.empty()) {
    s.first_time = t.front();
    s.last_time = t.back();
  }
  if (t.size() > 1) {
    std::vector<double> dt(t.size() - 1);
    for (std::size_t i = 1; i < t.size(); ++i) dt[i - 1] = t[i] - t[i - 1];
    std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
    s.median_interval = dt[dt.size() / 2];
  }
  const std::size_t n = std::min(scans_to_read, source.size());
  double points = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = n == 1 ? 0 : k * (source.size() - 1) / (n - 1);
    const LabelledCloud cloud = source.scan(i);
    points += static_cast<double>(cloud.size());
    if (k == 0) {
      s.beams = estimate_beams(cloud);
      s.per_point_times = cloud.has_times();
      if (cloud.has_times()) {
        const auto [lo, hi] = std::minmax_element(cloud.time.begin(), cloud.time.end());
        s.sweep_seconds = static_cast<double>(*hi - *lo);
      }
    }
  }
  s.scans_read = n;
  s.mean_points = n > 0 ? points / static_cast<double>(n) : 0.0;
  s.fields = info.point_fields;
  s.labels = info.has_labels;
  s.calibration = info.velo_to_cam.has_value();
  if (info.camera_poses) s.reference_poses = info.camera_poses->size();
  s.notes = info.notes;
  return s;
}

}  // namespace saloam
