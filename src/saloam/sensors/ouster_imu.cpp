#include "saloam/sensors/ouster_imu.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <initializer_list>
#include <numbers>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "saloam/core/error.hpp"
#include "saloam/io/text_input.hpp"
#include "saloam/sensors/pcap_reader.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace saloam {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

/// The little-endian unsigned integer of `bytes` bytes at `offset`.
std::uint64_t read_le(std::span<const std::byte> p, std::size_t offset, std::size_t bytes) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < bytes; ++i) v |= std::to_integer<std::uint64_t>(p[offset + i]) << (8 * i);
  return v;
}

double read_f32(std::span<const std::byte> p, std::size_t offset) {
  return static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(read_le(p, offset, 4))));
}

/// The node at a "/"-separated path, or nullptr (null counts as absent).
const json* find(const json& root, std::string_view path) {
  const json* node = &root;
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

/// The first of `paths` present, or nullptr.
const json* find_any(const json& root, std::initializer_list<std::string_view> paths) {
  for (const auto path : paths) {
    if (const json* node = find(root, path)) return node;
  }
  return nullptr;
}

/// A 4x4 row-major rigid transform at `path`, checked.
Eigen::Matrix4d read_transform(const json& root, std::string_view path, const fs::path& file) {
  const json* node = find(root, path);
  if (!node) throw InputError(file, fmt::format("Ouster metadata without \"{}\"", path));
  if (!node->is_array() || node->size() != 16) {
    throw InputError(file, fmt::format("Ouster metadata \"{}\": expected a list of 16 numbers", path));
  }
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) {
    const json& v = (*node)[static_cast<std::size_t>(i)];
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      throw InputError(file, fmt::format("Ouster metadata \"{}\": unexpected value {}", path,
                                         plain_error_text(v.dump(), 80)));
    }
    m(i / 4, i % 4) = v.get<double>();
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const double off_orthogonal = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm();
  if (off_orthogonal > 1e-3 || r.determinant() < 0.0) {
    throw InputError(file, fmt::format("Ouster metadata \"{}\": its rotation is not one (|R^T R - I| = {:.3g}, "
                                       "det {:.3g})", path, off_orthogonal, r.determinant()));
  }
  if (m.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
    throw InputError(file, fmt::format("Ouster metadata \"{}\": last row is not 0 0 0 1", path));
  }
  return m;
}

std::uint16_t read_port(const json* node, std::string_view key, const fs::path& file) {
  if (!node) return 7503;
  if (!node->is_number_integer() || node->get<std::int64_t>() < 1 || node->get<std::int64_t>() > 65535) {
    throw InputError(file, fmt::format("Ouster metadata \"{}\": {} is not a port (1..65535)", key,
                                       plain_error_text(node->dump(), 40)));
  }
  return static_cast<std::uint16_t>(node->get<std::int64_t>());
}

}  // namespace

std::optional<ImuSample> decode_ouster_imu_packet(std::span<const std::byte> payload) {
  if (payload.size() != kOusterImuPacketBytes) return std::nullopt;
  ImuSample s;
  s.time = static_cast<double>(read_le(payload, 8, 8)) * 1e-9;
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    s.acceleration[i] = read_f32(payload, 24 + 4 * k) * kStandardGravity;
    s.angular_velocity[i] = read_f32(payload, 36 + 4 * k) * kDegToRad;
  }
  if (!s.acceleration.allFinite() || !s.angular_velocity.allFinite()) return std::nullopt;
  return s;
}

std::vector<ImuSample> read_ouster_imu(const fs::path& pcap, std::uint16_t imu_port, ImuReadCounts* counts) {
  PcapReader reader(pcap);
  ImuReadCounts c;
  std::vector<ImuSample> samples;
  UdpDatagram d;
  while (reader.next(d)) {
    if (d.dst_port != imu_port) continue;
    ++c.datagrams;
    if (d.payload.size() != kOusterImuPacketBytes) {
      ++c.wrong_size;
    } else if (const auto s = decode_ouster_imu_packet(std::as_bytes(std::span(d.payload)))) {
      samples.push_back(*s);
    } else {
      ++c.non_finite;
    }
  }
  if (counts) *counts = c;
  return samples;
}

Eigen::Matrix3d OusterImuCalibration::imu_to_lidar_rotation() const {
  return lidar_to_sensor.topLeftCorner<3, 3>().transpose() * imu_to_sensor.topLeftCorner<3, 3>();
}

OusterImuCalibration parse_ouster_imu_calibration(std::string_view text, const fs::path& file) {
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(file, fmt::format("not JSON (Ouster metadata expected): {}", e.what()));
  }
  if (!root.is_object()) throw InputError(file, "not a JSON object (Ouster metadata expected)");
  const bool nested = root.contains("sensor_info") || root.contains("lidar_data_format") ||
                      root.contains("beam_intrinsics") || root.contains("imu_intrinsics");
  OusterImuCalibration c;
  const std::string_view port_key = nested ? "config_params/udp_port_imu" : "udp_port_imu";
  c.udp_port_imu = read_port(find(root, port_key), port_key, file);
  c.imu_to_sensor =
      read_transform(root, nested ? "imu_intrinsics/imu_to_sensor_transform" : "imu_to_sensor_transform", file);
  c.lidar_to_sensor =
      read_transform(root, nested ? "lidar_intrinsics/lidar_to_sensor_transform" : "lidar_to_sensor_transform", file);
  const json* profile = nested ? find_any(root, {"lidar_data_format/udp_profile_imu", "config_params/udp_profile_imu"})
                               : find(root, "data_format/udp_profile_imu");
  if (profile && (!profile->is_string() || profile->get<std::string>() != "LEGACY")) {
    throw InputError(file, fmt::format("udp_profile_imu {} is not one saloam decodes (LEGACY, 48-byte packets)",
                                       plain_error_text(profile->dump(), 60)));
  }
  return c;
}

OusterImuCalibration read_ouster_imu_calibration(const fs::path& file) {
  return parse_ouster_imu_calibration(open_text_file(file, "Ouster metadata").str(), file);
}

}  // namespace saloam
