#include "saloam/core/sensor_profile.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/yaml_documents.hpp"

namespace saloam {
namespace {

const YAML::Node required(const YAML::Node& map, const std::string& key, const std::filesystem::path& file) {
  if (!map.IsMap() || !map[key]) throw InputError(file, fmt::format("sensor profile without '{}'", key));
  return map[key];
}

template <class T>
T value(const YAML::Node& map, const std::string& key, const std::filesystem::path& file) {
  const YAML::Node node = required(map, key, file);
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw InputError(file, fmt::format("'{}' of the sensor profile has the wrong type", key));
  }
}

// A profile of 1024 lasers is about 10 kB.
constexpr std::size_t kMaxProfileBytes = std::size_t{1} << 20;

/// InputError when a key of the map `node` is not a name or is given twice.
void check_keys(const YAML::Node& node, const std::string& section, const std::filesystem::path& file) {
  if (const auto problem = key_problem(node, section); !problem.empty()) throw InputError(file, problem);
}

void check(const SensorProfile& p, const std::filesystem::path& file) {
  const auto& e = p.elevation_deg;
  if (e.empty()) throw InputError(file, "'elevation_deg' lists no laser");
  if (e.size() > kMaxSensorLasers) {
    throw InputError(file, fmt::format("'elevation_deg' lists {} lasers, more than {}", e.size(), kMaxSensorLasers));
  }
  for (std::size_t i = 0; i < e.size(); ++i) {
    if (!(e[i] >= -90.0 && e[i] <= 90.0)) throw InputError(file, fmt::format("elevation_deg[{}] = {} is not in [-90, 90]", i, e[i]));
    if (i > 0 && !(e[i] < e[i - 1])) {
      throw InputError(file, fmt::format("elevation_deg[{}] = {} does not lie below {} (top laser first)", i, e[i], e[i - 1]));
    }
  }
  if (!(p.min_range >= 0.0 && p.min_range < p.max_range && p.max_range <= 10000.0)) {
    throw InputError(file, fmt::format("ranges: need 0 <= min_range < max_range <= 10000 [m], got {} and {}", p.min_range,
                                       p.max_range));
  }
  if (!(p.sweep_duration > 0.0 && p.sweep_duration <= 10.0)) {
    throw InputError(file, fmt::format("sweep_duration = {} is not in (0, 10] [s]", p.sweep_duration));
  }
  if (!(p.sweep_start_azimuth_deg >= -360.0 && p.sweep_start_azimuth_deg <= 360.0)) {
    throw InputError(file, fmt::format("sweep_start_azimuth_deg = {} is not in [-360, 360]", p.sweep_start_azimuth_deg));
  }
  if (p.simulation.azimuth_steps < 16 || p.simulation.azimuth_steps > 8000) {
    throw InputError(file, fmt::format("simulation.azimuth_steps = {} is not in [16, 8000]", p.simulation.azimuth_steps));
  }
  if (!(p.simulation.mount_height > 0.0 && p.simulation.mount_height <= 100.0) ||
      !(p.simulation.range_noise >= 0.0 && p.simulation.range_noise <= 1.0)) {
    throw InputError(file, "simulation: mount_height must lie in (0, 100] [m] and range_noise in [0, 1] [m]");
  }
}

}  // namespace

SensorProfile parse_sensor_profile(std::string_view yaml, const std::filesystem::path& file) {
  const YamlDocument document = load_yaml_document(yaml, "a sensor profile");
  if (!document.problem.empty()) throw InputError(file, document.problem);
  const YAML::Node& root = document.root;
  check_keys(root, "", file);
  if (root.IsMap() && root["simulation"]) check_keys(root["simulation"], "simulation", file);
  SensorProfile p;
  p.name = value<std::string>(root, "name", file);
  p.model = value<std::string>(root, "model", file);
  p.elevation_deg = value<std::vector<double>>(root, "elevation_deg", file);
  p.min_range = value<double>(root, "min_range", file);
  p.max_range = value<double>(root, "max_range", file);
  p.sweep_duration = value<double>(root, "sweep_duration", file);
  p.sweep_clockwise = value<bool>(root, "sweep_clockwise", file);
  p.sweep_start_azimuth_deg = value<double>(root, "sweep_start_azimuth_deg", file);
  const YAML::Node sim = required(root, "simulation", file);
  p.simulation.azimuth_steps = value<int>(sim, "azimuth_steps", file);
  p.simulation.mount_height = value<double>(sim, "mount_height", file);
  p.simulation.range_noise = value<double>(sim, "range_noise", file);
  const auto body = value<std::string>(sim, "ego_body", file);
  if (body != "kitti" && body != "none") throw InputError(file, fmt::format("simulation.ego_body '{}': kitti or none", body));
  p.simulation.kitti_ego_body = body == "kitti";
  check(p, file);
  return p;
}

SensorProfile load_sensor_profile(const std::filesystem::path& file) {
  return parse_sensor_profile(read_file(file, kMaxProfileBytes, "sensor profile"), file);
}

std::vector<SensorProfile> load_sensor_profiles(const std::filesystem::path& folder) {
  std::error_code error;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    if (entry.path().extension() == ".yaml") files.push_back(entry.path());
  }
  if (error) throw InputError(folder, fmt::format("cannot list the sensor profiles: {}", error.message()));
  std::vector<SensorProfile> profiles;
  for (const auto& f : files) profiles.push_back(load_sensor_profile(f));
  std::sort(profiles.begin(), profiles.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  for (std::size_t i = 1; i < profiles.size(); ++i) {
    if (profiles[i].name == profiles[i - 1].name) throw InputError(folder, fmt::format("two profiles named '{}'", profiles[i].name));
  }
  return profiles;
}

void apply_sensor_profile(const SensorProfile& profile, FeatureConfig& features) {
  features.num_beams = profile.beams();
  features.beam_elevations_deg = profile.elevation_deg;
  features.sweep_duration = profile.sweep_duration;
  features.sweep_clockwise = profile.sweep_clockwise;
  features.sweep_start_azimuth_deg = profile.sweep_start_azimuth_deg;
  features.max_range = std::min(features.max_range, profile.max_range);
  features.min_range = std::max(features.min_range, profile.min_range);
  features.pose_time_in_sweep = std::min(features.pose_time_in_sweep, features.sweep_duration);
}

}  // namespace saloam
