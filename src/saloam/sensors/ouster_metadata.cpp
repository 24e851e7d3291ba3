#include "saloam/sensors/ouster_metadata.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <type_traits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/io/text_input.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace saloam {
namespace {

constexpr std::array<std::pair<OusterProfile, std::string_view>, 6> kProfiles{{
    {OusterProfile::kLegacy, "LEGACY"},
    {OusterProfile::kRng19Rfl8Sig16Nir16, "RNG19_RFL8_SIG16_NIR16"},
    {OusterProfile::kRng19Rfl8Sig16Nir16Dual, "RNG19_RFL8_SIG16_NIR16_DUAL"},
    {OusterProfile::kRng15Rfl8Nir8, "RNG15_RFL8_NIR8"},
    {OusterProfile::kRng15Rfl8Nir8Dual, "RNG15_RFL8_NIR8_DUAL"},
    {OusterProfile::kFusaRng15Rfl8Nir8Dual, "FUSA_RNG15_RFL8_NIR8_DUAL"},
}};

constexpr std::uint32_t kMaxColumns = 4096;  // the widest mode is 4096x5
constexpr std::uint32_t kMaxColumnsPerPacket = 64;
constexpr std::uint32_t kMaxPixels = 256;

/// Reads the keys of one metadata file, each error naming the file and key.
class Reader {
 public:
  Reader(const json& root, const fs::path& file) : root_(root), file_(file) {}

  /// The object at a "/"-separated path, or nullptr.
  [[nodiscard]] const json* find(std::string_view path) const {
    const json* node = &root_;
    std::size_t start = 0;
    while (start <= path.size()) {
      const std::size_t slash = std::min(path.find('/', start), path.size());
      const std::string key(path.substr(start, slash - start));
      if (!node->is_object() || !node->contains(key)) return nullptr;
      node = &(*node)[key];
      start = slash + 1;
    }
    return node->is_null() ? nullptr : node;
  }
  [[nodiscard]] const json& need(std::string_view path) const {
    const json* node = find(path);
    if (!node) throw InputError(file_, fmt::format("Ouster metadata without \"{}\"", path));
    return *node;
  }
  template <class T>
  [[nodiscard]] T get(std::string_view path) const {
    return as<T>(need(path), path);
  }
  template <class T>
  [[nodiscard]] T get_or(std::string_view path, T fallback) const {
    const json* node = find(path);
    return node ? as<T>(*node, path) : fallback;
  }
  template <class T>
  [[nodiscard]] std::vector<T> list(std::string_view path, std::size_t n) const {
    const json& node = need(path);
    if (!node.is_array() || node.size() != n) {
      throw InputError(file_, fmt::format("Ouster metadata \"{}\": expected a list of {} numbers", path, n));
    }
    std::vector<T> out;
    for (const auto& v : node) out.push_back(as<T>(v, path));
    return out;
  }
  [[nodiscard]] Eigen::Matrix4d matrix(std::string_view path) const {
    const auto v = list<double>(path, 16);
    Eigen::Matrix4d m;
    for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = v[static_cast<std::size_t>(i)];
    return m;
  }
  [[noreturn]] void fail(const std::string& problem) const { throw InputError(file_, "Ouster metadata: " + problem); }

 private:
  template <class T>
  T as(const json& node, std::string_view path) const {
    if constexpr (std::is_same_v<T, std::string>) {
      if (node.is_string()) return node.get<std::string>();
    } else if constexpr (std::is_floating_point_v<T>) {
      if (node.is_number()) return node.get<T>();
    } else {
      if (node.is_number_integer()) {
        const auto v = node.get<std::int64_t>();
        if (v >= std::numeric_limits<T>::min() && v <= std::numeric_limits<T>::max()) return static_cast<T>(v);
      }
    }
    throw InputError(file_, fmt::format("Ouster metadata \"{}\": unexpected value {}", path,
                                        plain_error_text(node.dump(), 80)));
  }

  const json& root_;
  const fs::path& file_;
};

/// "1024x10" -> 1024 columns at 10 Hz.
std::pair<std::uint32_t, double> parse_lidar_mode(const std::string& mode, const Reader& in) {
  const auto x = mode.find('x');
  std::uint32_t columns = 0;
  int hz = 0;
  const bool ok = x != std::string::npos &&
                  std::from_chars(mode.data(), mode.data() + x, columns).ec == std::errc{} &&
                  std::from_chars(mode.data() + x + 1, mode.data() + mode.size(), hz).ec == std::errc{} && hz > 0;
  if (!ok) in.fail(fmt::format("lidar_mode \"{}\" is not COLUMNSxHZ", plain_error_text(mode, 40)));
  return {columns, static_cast<double>(hz)};
}

OusterProfile parse_profile(const std::string& name, const Reader& in) {
  for (const auto& [profile, n] : kProfiles) {
    if (n == name) return profile;
  }
  in.fail(fmt::format("udp_profile_lidar \"{}\" is not one saloam decodes (LEGACY, RNG19_RFL8_SIG16_NIR16[_DUAL], "
                      "RNG15_RFL8_NIR8[_DUAL], FUSA_RNG15_RFL8_NIR8_DUAL)",
                      plain_error_text(name, 60)));
}

/// Where each key sits in the two layouts.
struct Paths {
  std::string_view prod_line, serial, firmware, lidar_mode, data_format, altitude, azimuth, origin, lidar_to_sensor,
      port_lidar, port_imu;
};
constexpr Paths kFlat{"prod_line", "prod_sn", "build_rev", "lidar_mode", "data_format", "beam_altitude_angles",
                      "beam_azimuth_angles", "lidar_origin_to_beam_origin_mm", "lidar_to_sensor_transform",
                      "udp_port_lidar", "udp_port_imu"};
constexpr Paths kNested{"sensor_info/prod_line", "sensor_info/prod_sn", "sensor_info/build_rev",
                        "config_params/lidar_mode", "lidar_data_format", "beam_intrinsics/beam_altitude_angles",
                        "beam_intrinsics/beam_azimuth_angles", "beam_intrinsics/lidar_origin_to_beam_origin_mm",
                        "lidar_intrinsics/lidar_to_sensor_transform", "config_params/udp_port_lidar",
                        "config_params/udp_port_imu"};

std::string df(std::string_view data_format, std::string_view key) { return fmt::format("{}/{}", data_format, key); }

void read_format(const Reader& in, const Paths& p, OusterMetadata& m) {
  const auto [mode_columns, hz] = parse_lidar_mode(m.lidar_mode, in);
  m.frequency_hz = hz;
  m.columns_per_frame = in.get_or<std::uint32_t>(df(p.data_format, "columns_per_frame"), mode_columns);
  m.columns_per_packet = in.get_or<std::uint32_t>(df(p.data_format, "columns_per_packet"), 16);
  const json* altitude = in.find(p.altitude);
  const auto beams = static_cast<std::uint32_t>(altitude && altitude->is_array() ? altitude->size() : 0);
  m.pixels_per_column = in.get_or<std::uint32_t>(df(p.data_format, "pixels_per_column"), beams);
  if (m.columns_per_frame == 0 || m.columns_per_frame > kMaxColumns) {
    in.fail(fmt::format("columns_per_frame {} out of 1..{}", m.columns_per_frame, kMaxColumns));
  }
  if (m.columns_per_packet == 0 || m.columns_per_packet > kMaxColumnsPerPacket ||
      m.columns_per_frame % m.columns_per_packet != 0) {
    in.fail(fmt::format("columns_per_packet {} is not within 1..{} and a divisor of columns_per_frame {}",
                        m.columns_per_packet, kMaxColumnsPerPacket, m.columns_per_frame));
  }
  if (m.pixels_per_column == 0 || m.pixels_per_column > kMaxPixels) {
    in.fail(fmt::format("pixels_per_column {} out of 1..{}", m.pixels_per_column, kMaxPixels));
  }
  m.column_window = {0, m.columns_per_frame - 1};
  if (in.find(df(p.data_format, "column_window"))) {
    const auto w = in.list<std::uint32_t>(df(p.data_format, "column_window"), 2);
    if (w[0] >= m.columns_per_frame || w[1] >= m.columns_per_frame) {
      in.fail(fmt::format("column_window [{}, {}] outside 0..{}", w[0], w[1], m.columns_per_frame - 1));
    }
    m.column_window = {w[0], w[1]};
  }
  m.pixel_shift_by_row.assign(m.pixels_per_column, 0);
  if (in.find(df(p.data_format, "pixel_shift_by_row"))) {
    m.pixel_shift_by_row = in.list<int>(df(p.data_format, "pixel_shift_by_row"), m.pixels_per_column);
  }
  const std::string profile = in.get_or<std::string>(df(p.data_format, "udp_profile_lidar"), "LEGACY");
  m.profile = parse_profile(profile, in);
}

// A rigid transform [mm]: a rotation (orthonormal within kRotationTolerance, det +1), a
// translation within 10 m, the last row 0 0 0 1; else the points it maps
// would be scaled, sheared or moved anywhere.
void check_rigid(const Reader& in, const Eigen::Matrix4d& T, const char* name) {
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const bool rigid = T.allFinite() && orthonormality_error(R) < kRotationTolerance &&
                     R.determinant() > 0 && T.topRightCorner<3, 1>().norm() <= 10000.0 &&
                     T.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1));
  if (!rigid) in.fail(fmt::format("{} is not a rigid transform (rotation and a translation within 10 m)", name));
}

// Each beam's angles finite and within a half turn (elevations a quarter):
// real ones are within a few degrees of the nominal pattern.
void check_angles(const Reader& in, const std::vector<double>& angles, double bound, const char* name) {
  for (std::size_t i = 0; i < angles.size(); ++i) {
    if (!std::isfinite(angles[i]) || std::abs(angles[i]) > bound) {
      in.fail(fmt::format("{}[{}] = {} is not within +-{} deg", name, i, angles[i], bound));
    }
  }
}

void read_beams(const Reader& in, const Paths& p, bool nested, OusterMetadata& m) {
  m.beam_altitude_angles = in.list<double>(p.altitude, m.pixels_per_column);
  m.beam_azimuth_angles = in.list<double>(p.azimuth, m.pixels_per_column);
  check_angles(in, m.beam_altitude_angles, 90.0, "beam_altitude_angles");
  check_angles(in, m.beam_azimuth_angles, 180.0, "beam_azimuth_angles");
  m.lidar_origin_to_beam_origin_mm = in.get<double>(p.origin);
  if (!std::isfinite(m.lidar_origin_to_beam_origin_mm) || std::abs(m.lidar_origin_to_beam_origin_mm) > 1000.0) {
    in.fail(fmt::format("lidar_origin_to_beam_origin_mm {} is not within +-1000 mm", m.lidar_origin_to_beam_origin_mm));
  }
  m.beam_to_lidar = Eigen::Matrix4d::Identity();
  if (nested && in.find("beam_intrinsics/beam_to_lidar_transform")) {
    m.beam_to_lidar = in.matrix("beam_intrinsics/beam_to_lidar_transform");
  } else {
    m.beam_to_lidar(0, 3) = m.lidar_origin_to_beam_origin_mm;
  }
  m.lidar_to_sensor = in.matrix(p.lidar_to_sensor);
  check_rigid(in, m.beam_to_lidar, "beam_to_lidar_transform");
  check_rigid(in, m.lidar_to_sensor, "lidar_to_sensor_transform");
}

}  // namespace

std::string_view ouster_profile_name(OusterProfile profile) {
  for (const auto& [p, name] : kProfiles) {
    if (p == profile) return name;
  }
  return "?";
}

std::uint32_t OusterMetadata::packets_per_frame() const {
  const std::uint32_t first = column_window.first / columns_per_packet;
  const std::uint32_t last = column_window.second / columns_per_packet;
  // A window that wraps past column 0 (first > last) covers both ends.
  return first <= last ? last - first + 1 : (columns_per_frame / columns_per_packet) - first + last + 1;
}

OusterMetadata parse_ouster_metadata(std::string_view text, const fs::path& file) {
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(file, fmt::format("not JSON (Ouster metadata expected): {}", e.what()));
  }
  if (!root.is_object()) throw InputError(file, "not a JSON object (Ouster metadata expected)");
  const Reader in(root, file);
  OusterMetadata m;
  m.nested_layout = root.contains("sensor_info") || root.contains("lidar_data_format") ||
                    root.contains("beam_intrinsics");
  const Paths& p = m.nested_layout ? kNested : kFlat;
  m.prod_line = in.get_or<std::string>(p.prod_line, "");
  m.firmware = in.get_or<std::string>(p.firmware, "");
  if (const json* sn = in.find(p.serial)) m.serial = sn->is_string() ? sn->get<std::string>() : sn->dump();
  m.lidar_mode = in.get<std::string>(p.lidar_mode);
  read_format(in, p, m);
  read_beams(in, p, m.nested_layout, m);
  m.udp_port_lidar = in.get_or<std::uint16_t>(p.port_lidar, 7502);
  m.udp_port_imu = in.get_or<std::uint16_t>(p.port_imu, 7503);
  return m;
}

OusterMetadata read_ouster_metadata(const fs::path& file) {
  return parse_ouster_metadata(open_text_file(file, "Ouster metadata").str(), file);
}

}  // namespace saloam
