// Rings of a scan (rings.hpp: scan_rings, rings_from_point_order, the beam
// layouts) and each point's time in the sweep.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "saloam/core/parallel.hpp"
#include "saloam/scan/rings.hpp"

namespace saloam {

int ring_count(BeamLayout layout) {
  switch (layout) {
    case BeamLayout::kHdl64: return 64;
    case BeamLayout::kHdl32: return 32;
    case BeamLayout::kVlp16: return 16;
  }
  return 64;
}

BeamLayout detect_beam_layout(const std::vector<Eigen::Vector3f>& points, int num_beams) {
  if (num_beams == 64) return BeamLayout::kHdl64;
  if (num_beams == 32) return BeamLayout::kHdl32;
  if (num_beams == 16) return BeamLayout::kVlp16;
  // Elevation range: HDL-64E +2..-24.9, HDL-32E +10.7..-30.7, VLP-16 +15..-15.
  // Robust percentiles instead of extremes (noise, reflections).
  std::vector<float> elevation;
  elevation.reserve(points.size() / 8 + 1);
  for (std::size_t i = 0; i < points.size(); i += 8) {
    const auto& p = points[i];
    elevation.push_back(std::atan2(p.z(), std::hypot(p.x(), p.y())) * 180.0f / static_cast<float>(M_PI));
  }
  if (elevation.empty()) return BeamLayout::kHdl64;
  std::sort(elevation.begin(), elevation.end());
  const float low = elevation[elevation.size() / 50];
  const float high = elevation[elevation.size() - 1 - elevation.size() / 50];
  if (high > 12.0f && low > -17.0f) return BeamLayout::kVlp16;
  if (low < -27.0f || high > 6.0f) return BeamLayout::kHdl32;
  return BeamLayout::kHdl64;
}

int ring_from_elevation(double elevation_deg, BeamLayout layout) {
  switch (layout) {
    case BeamLayout::kHdl64: {
      constexpr double kUpperTop = 2.0, kUpperBottom = -8.33, kLowerTop = -8.83, kLowerBottom = -24.9;
      constexpr double kUpperStep = (kUpperTop - kUpperBottom) / 31.0;
      constexpr double kLowerStep = (kLowerTop - kLowerBottom) / 31.0;
      if (elevation_deg > kUpperTop + kUpperStep || elevation_deg < kLowerBottom - kLowerStep) return -1;
      if (elevation_deg >= 0.5 * (kUpperBottom + kLowerTop)) {
        const int ring = static_cast<int>(std::lround((kUpperTop - elevation_deg) / kUpperStep));
        return std::clamp(ring, 0, 31);
      }
      const int ring = 32 + static_cast<int>(std::lround((kLowerTop - elevation_deg) / kLowerStep));
      return std::clamp(ring, 32, 63);
    }
    case BeamLayout::kHdl32: {
      constexpr double kTop = 10.67, kStep = 4.0 / 3.0;
      const int ring = static_cast<int>(std::lround((kTop - elevation_deg) / kStep));
      return (ring < -1 || ring > 32) ? -1 : std::clamp(ring, 0, 31);
    }
    case BeamLayout::kVlp16: {
      constexpr double kTop = 15.0, kStep = 2.0;
      const int ring = static_cast<int>(std::lround((kTop - elevation_deg) / kStep));
      return (ring < -1 || ring > 16) ? -1 : std::clamp(ring, 0, 15);
    }
  }
  return -1;
}

namespace {
/// sweep_time_from_azimuth with the start angle converted once per scan.
class SweepClock {
 public:
  explicit SweepClock(const FeatureConfig& config)
      : start_(config.sweep_start_azimuth_deg * M_PI / 180.0),
        clockwise_(config.sweep_clockwise),
        duration_(config.sweep_duration) {}
  [[nodiscard]] double time(double azimuth_rad) const {
    double turned = clockwise_ ? start_ - azimuth_rad : azimuth_rad - start_;
    // fmod returns its argument unchanged below one turn, the usual case.
    if (std::abs(turned) >= 2.0 * M_PI) turned = std::fmod(turned, 2.0 * M_PI);
    if (turned < 0.0) turned += 2.0 * M_PI;
    return turned / (2.0 * M_PI) * duration_;
  }

 private:
  double start_;  ///< [rad]
  bool clockwise_;
  double duration_;  ///< [s]
};
}  // namespace

double sweep_time_from_azimuth(double azimuth_rad, const FeatureConfig& config) {
  return SweepClock(config).time(azimuth_rad);
}

std::vector<float> point_sweep_times(const LabelledCloud& cloud, const FeatureConfig& config, bool parallel) {
  std::vector<float> times(cloud.size(), -1.0f);  // -1: on the sensor axis, unusable
  const SweepClock clock(config);
  for_each_index(cloud.size(), parallel, 4096, [&](std::size_t i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (std::abs(p.x()) + std::abs(p.y()) < 1e-3f) return;
    times[i] = static_cast<float>(clock.time(std::atan2(p.y(), p.x())));
  });
  return times;
}

namespace {

// A ring is a run of points whose phase (fraction of a turn from the seam,
// in the storage's turning sense) increases: the storage moves to the next
// ring where the phase jumps back by more than half a turn.
bool starts_next_ring(double last, double phase) { return last >= 0.0 && phase < last - 0.5; }

/// How many runs split_rings cuts `phase` into, before its acceptance test.
std::size_t run_count(const std::vector<float>& phase) {
  std::size_t runs = 0;
  double last = -1.0;
  for (const float p : phase) {
    if (p < 0.0f) continue;
    runs += last < 0.0 || starts_next_ring(last, p);
    last = p;
  }
  return runs;
}

std::vector<std::vector<std::uint32_t>> split_rings(const std::vector<float>& phase, int expected_rings) {
  std::vector<std::vector<std::uint32_t>> rings;
  std::vector<std::uint32_t> current;
  double last = -1.0;
  for (std::size_t i = 0; i < phase.size(); ++i) {
    const double p = phase[i];
    if (p < 0.0) continue;
    if (starts_next_ring(last, p)) {
      rings.push_back(std::move(current));
      current.clear();
    }
    current.push_back(static_cast<std::uint32_t>(i));
    last = p;
  }
  if (!current.empty()) rings.push_back(std::move(current));
  // Accept only if it looks like rings: many long runs, not more runs than
  // a spinning LiDAR has beams (expected_rings <= 0: any of 16..128).
  int long_runs = 0;
  for (const auto& r : rings) long_runs += r.size() >= 100;
  const int segments = static_cast<int>(rings.size());
  const int max_rings = expected_rings > 0 ? expected_rings * 3 / 2 + 2 : 130;
  const int min_long = expected_rings > 0 ? expected_rings / 4 : 8;
  if (long_runs < min_long || segments > max_rings) return {};
  return rings;
}

/// The phases in the order the points are stored, when it is not the
/// sweep's: the sense is that of most small steps between consecutive points
/// (at least 90 % of them; large steps are ring changes or gaps), the seam
/// where the first ring starts. Empty when no sense dominates (the points are
/// not stored along rings). `sweep_phase` is the phase in the sweep's own
/// order; a phase is a linear function of the azimuth, so no angle is recomputed.
std::vector<float> storage_phase(const std::vector<float>& sweep_phase) {
  constexpr float kSmallStep = 5.0f / 360.0f;
  std::size_t along = 0, against = 0;
  const auto valid = std::find_if(sweep_phase.begin(), sweep_phase.end(), [](float p) { return p >= 0.0f; });
  if (valid == sweep_phase.end()) return {};
  const float first = *valid;
  float previous = first;
  for (auto it = valid + 1; it != sweep_phase.end(); ++it) {
    const float p = *it;
    if (p < 0.0f) continue;
    float step = p - previous;
    if (step > 0.5f) step -= 1.0f;
    if (step < -0.5f) step += 1.0f;
    along += step > 0.0f && step < kSmallStep;
    against += step < 0.0f && step > -kSmallStep;
    previous = p;
  }
  const std::size_t steps = along + against;
  if (steps < 100 || static_cast<double>(std::max(along, against)) < 0.9 * static_cast<double>(steps)) return {};
  const float sense = along > against ? 1.0f : -1.0f;
  std::vector<float> phase(sweep_phase.size(), -1.0f);
  for (std::size_t i = 0; i < phase.size(); ++i) {
    if (sweep_phase[i] < 0.0f) continue;
    const float turned = sense * (sweep_phase[i] - first);
    phase[i] = turned - std::floor(turned);
  }
  return phase;
}

/// Rings from the storage order, given every point's sweep time, split in
/// two ways: in the sweep's own order (the simulator stores rings in firing
/// order) and in the order detected in the scan (KITTI stores each ring
/// counter-clockwise from azimuth 0, although the HDL-64E fires clockwise
/// from behind). A seam in the wrong place cuts every ring in two and makes
/// one run more than there are rings, so the split with fewer runs wins; the
/// sweep's on a tie (its seam does not depend on where the first ring's
/// returns begin).
std::vector<std::vector<std::uint32_t>> rings_from_storage(const std::vector<float>& sweep_times,
                                                           const FeatureConfig& config, int expected_rings) {
  std::vector<float> sweep_phase(sweep_times.size());
  const auto duration = static_cast<float>(config.sweep_duration);
  std::transform(sweep_times.begin(), sweep_times.end(), sweep_phase.begin(),
                 [duration](float t) { return t < 0.0f ? -1.0f : t / duration; });
  auto rings = split_rings(sweep_phase, expected_rings);
  const auto phase = storage_phase(sweep_phase);
  // Only a split with fewer runs can win: count them before cutting.
  if (phase.empty() || (!rings.empty() && run_count(phase) >= rings.size())) return rings;
  auto detected = split_rings(phase, expected_rings);
  if (rings.empty() || !detected.empty()) return detected;
  return rings;
}
}  // namespace

std::vector<std::vector<std::uint32_t>> rings_from_point_order(const LabelledCloud& cloud,
                                                              const FeatureConfig& config, int expected_rings) {
  return rings_from_storage(point_sweep_times(cloud, config, false), config, expected_rings);
}

namespace {
/// Rings from the elevation angle (for scans not stored ring by ring), each
/// ordered in time so that ring neighbours are neighbours in azimuth.
std::vector<std::vector<std::uint32_t>> rings_from_elevation(const LabelledCloud& cloud,
                                                             const std::vector<float>& times,
                                                             const FeatureConfig& config) {
  struct Entry {
    float time;
    std::uint32_t index;
  };
  const BeamLayout layout = detect_beam_layout(cloud.points, config.num_beams);
  const int num_rings = ring_count(layout);
  std::vector<std::vector<Entry>> buckets(num_rings);
  for (auto& b : buckets) b.reserve(cloud.size() / num_rings * 2);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (times[i] < 0.0f) continue;
    const double horizontal = std::hypot(p.x(), p.y());
    const int ring = ring_from_elevation(std::atan2(p.z(), horizontal) * 180.0 / M_PI, layout);
    if (ring < 0) continue;
    buckets[ring].push_back({times[i], static_cast<std::uint32_t>(i)});
  }
  std::vector<std::vector<std::uint32_t>> rings(buckets.size());
  for (std::size_t r = 0; r < buckets.size(); ++r) {
    auto& bucket = buckets[r];
    std::sort(bucket.begin(), bucket.end(), [](const Entry& a, const Entry& b) { return a.time < b.time; });
    rings[r].reserve(bucket.size());
    for (const Entry& e : bucket) rings[r].push_back(e.index);
  }
  return rings;
}


}  // namespace

std::vector<std::vector<std::uint32_t>> rings_from_times(const LabelledCloud& cloud, const std::vector<float>& times,
                                                         const FeatureConfig& config) {
  if (cloud.has_rings()) return rings_from_ring_field(cloud, times);
  const auto& lasers = config.beam_elevations_deg;
  std::vector<std::vector<std::uint32_t>> rings;
  const int expected = config.num_beams > 0 ? config.num_beams : static_cast<int>(lasers.size());
  if (config.ring_from_point_order) rings = rings_from_storage(times, config, expected);
  if (rings.empty()) rings = lasers.empty() ? rings_from_elevation(cloud, times, config)
                                            : rings_from_laser_elevations(cloud, times, lasers);
  return rings;
}

std::vector<std::vector<std::uint32_t>> scan_rings(const LabelledCloud& cloud, const FeatureConfig& config) {
  return rings_from_times(cloud, point_sweep_times(cloud, config, false), config);
}

}  // namespace saloam
