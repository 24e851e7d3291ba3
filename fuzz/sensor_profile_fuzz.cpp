// Sensor profiles (parse_sensor_profile, what load_sensor_profile reads
// files with). Accepted text must give a profile that keeps every promise of
// core/sensor_profile.hpp and that the odometry's settings take
// (apply_sensor_profile, then validate_config).

#include <algorithm>
#include <cmath>

#include "fuzz_support.hpp"
#include "saloam/core/sensor_profile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  const std::filesystem::path origin = "/sensors/lidar.yaml";
  SensorProfile p;
  try {
    p = parse_sensor_profile(fuzz::as_text(data, size), origin);
  } catch (const InputError& e) {
    SALOAM_FUZZ_CHECK(e.file() == origin);
    return 0;
  }
  SALOAM_FUZZ_CHECK(!p.elevation_deg.empty() && p.elevation_deg.size() <= kMaxSensorLasers);
  for (std::size_t i = 0; i < p.elevation_deg.size(); ++i) {
    SALOAM_FUZZ_CHECK(p.elevation_deg[i] >= -90.0 && p.elevation_deg[i] <= 90.0);
    if (i > 0) SALOAM_FUZZ_CHECK(p.elevation_deg[i] < p.elevation_deg[i - 1]);
  }
  SALOAM_FUZZ_CHECK(p.min_range >= 0.0 && p.min_range < p.max_range && std::isfinite(p.max_range));
  SALOAM_FUZZ_CHECK(p.sweep_duration > 0.0 && std::isfinite(p.sweep_duration));
  SALOAM_FUZZ_CHECK(std::isfinite(p.sweep_start_azimuth_deg));
  SALOAM_FUZZ_CHECK(p.simulation.azimuth_steps >= 16 && p.simulation.mount_height > 0.0);
  SaloamConfig config;
  apply_sensor_profile(p, config.odometry.features);
  try {
    validate_config(config, "profile");
  } catch (const ConfigError&) {
    // Only the ranges can clash: the configured ones narrowed to the sensor's
    // may leave nothing between them.
    const FeatureConfig defaults;
    SALOAM_FUZZ_CHECK(!(std::max(defaults.min_range, p.min_range) < std::min(defaults.max_range, p.max_range)));
  }
  return 0;
}
