#pragma once
// Sensor profiles: what saloam knows of a spinning LiDAR model, read from
// YAML. Shipped in config/sensors/NAME.yaml (installed with the other
// configuration files, <prefix>/share/saloam/config/sensors/): hdl64e
// (KITTI's), hdl32e, vlp16, os1-64, os1-128. The format, every key required:
//   name: vlp16                     what --sensor calls it
//   model: Velodyne VLP-16          for messages
//   elevation_deg: [15, 13, ...]    each laser's elevation [deg], top first, strictly decreasing
//   min_range: 0.5                  [m] nearest return the sensor reports
//   max_range: 100                  [m] farthest
//   sweep_duration: 0.1             [s] one revolution (10 Hz)
//   sweep_clockwise: true           seen from above (Velodyne and Ouster: true)
//   sweep_start_azimuth_deg: 180    where a published scan starts (atan2(y, x)): 180 = behind
//   simulation:                     how `saloam simulate --sensor NAME` renders it
//     azimuth_steps: 1800           firing positions per revolution
//     mount_height: 1.0             [m] above the road
//     ego_body: none                kitti: KITTI's car (sensor 1.73 m up) stops rays that meet it; none
//     range_noise: 0.03             [m] Gaussian sigma of the measured range
// Frames and units: the LiDAR frame (x forward, z up), metres, seconds;
// elevation = atan2(z, hypot(x, y)) in degrees.

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/config.hpp"

namespace saloam {

/// The most lasers a profile may list (the configuration's num_beams range).
inline constexpr std::size_t kMaxSensorLasers = 1024;

struct SensorSimulation {
  int azimuth_steps = 0;
  double mount_height = 0.0;  ///< [m]
  bool kitti_ego_body = false;
  double range_noise = 0.0;   ///< [m]
};

struct SensorProfile {
  std::string name;
  std::string model;
  std::vector<double> elevation_deg;  ///< top first
  double min_range = 0.0, max_range = 0.0;  ///< [m]
  double sweep_duration = 0.0;              ///< [s]
  bool sweep_clockwise = true;
  double sweep_start_azimuth_deg = 0.0;
  SensorSimulation simulation;

  [[nodiscard]] int beams() const { return static_cast<int>(elevation_deg.size()); }
  /// "vlp16 (Velodyne VLP-16)"
  [[nodiscard]] std::string title() const { return name + " (" + model + ")"; }
};

/// A profile from YAML text; InputError naming `file` for a missing or
/// malformed key, elevations that do not decrease (or more than
/// kMaxSensorLasers), ranges out of order or beyond 10 km, a sweep outside
/// (0, 10] s, a start azimuth outside [-360, 360] deg, or simulation values
/// outside their ranges (azimuth_steps [16, 8000], mount_height (0, 100] m,
/// range_noise [0, 1] m), a key given twice, or more than one YAML document.
SensorProfile parse_sensor_profile(std::string_view yaml, const std::filesystem::path& file);
/// The profile in `file` (a regular file of at most 1 MiB; core/files.hpp's read_file).
SensorProfile load_sensor_profile(const std::filesystem::path& file);
/// Every profile in `folder` (*.yaml), ordered by name; InputError when the
/// folder cannot be read, a file is malformed, or two files share a name.
std::vector<SensorProfile> load_sensor_profiles(const std::filesystem::path& folder);

/// The profile's facts in the odometry's settings: num_beams and
/// beam_elevations_deg, the sweep (duration, sense, start), max_range (the
/// smaller of both) and min_range (the larger: the configured one also keeps
/// out the vehicle's own body).
void apply_sensor_profile(const SensorProfile& profile, FeatureConfig& features);

}  // namespace saloam
