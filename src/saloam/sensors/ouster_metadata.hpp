#pragma once
// An Ouster sensor's metadata JSON (what the sensor reports at
// /api/v1/sensor/metadata and what its recording tools save beside a
// capture): everything needed to decode its lidar packets and place their
// points. Two layouts exist, both read:
//   flat (firmware 2.x, ouster_client <= 0.3): beam_altitude_angles,
//     beam_azimuth_angles, lidar_origin_to_beam_origin_mm,
//     lidar_to_sensor_transform, lidar_mode, prod_line, build_rev, and
//     data_format { columns_per_frame, columns_per_packet, pixels_per_column,
//     pixel_shift_by_row, column_window, udp_profile_lidar };
//   nested (firmware 2.4+ / 3.x): sensor_info, beam_intrinsics (with
//     beam_to_lidar_transform), lidar_intrinsics, lidar_data_format,
//     config_params, calibration_status.
// Missing in either: udp_profile_lidar means LEGACY (firmware before 2.2),
// columns_per_packet 16, column_window the whole sweep, pixel shifts 0,
// beam_to_lidar_transform the identity with lidar_origin_to_beam_origin_mm
// as its x translation (as the manufacturer's SDK takes them).
//
// Units as in the file: angles [deg], transforms 4x4 row-major with
// translations [mm]. The frames (Ouster's "Sensor Data" documentation):
// the lidar frame has +x towards the connector (behind), the sensor frame
// has +x forward and the origin at the base (lidar_to_sensor_transform:
// rotation by 180 deg about z and 36.18 mm up on OS1). Points come out in
// the sensor frame.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace saloam {

/// Lidar packet layouts (Ouster's udp_profile_lidar).
enum class OusterProfile {
  kLegacy,                      ///< LEGACY: 12-byte pixels, 16-byte column header, status in a 4-byte column footer
  kRng19Rfl8Sig16Nir16,         ///< single return, 12-byte pixels
  kRng19Rfl8Sig16Nir16Dual,     ///< two returns, 16-byte pixels
  kRng15Rfl8Nir8,               ///< low bandwidth, 4-byte pixels
  kRng15Rfl8Nir8Dual,           ///< low bandwidth, two returns, 8-byte pixels
  kFusaRng15Rfl8Nir8Dual,       ///< as above, with the FuSa packet header (32-bit frame id)
};

/// "LEGACY", "RNG19_RFL8_SIG16_NIR16", ...
[[nodiscard]] std::string_view ouster_profile_name(OusterProfile profile);

struct OusterMetadata {
  std::string prod_line;       ///< "OS-1-128"
  std::string serial;          ///< prod_sn
  std::string firmware;        ///< build_rev ("v2.3.0")
  std::string lidar_mode;      ///< "1024x10"
  double frequency_hz = 10.0;  ///< from lidar_mode (10 or 20)
  OusterProfile profile = OusterProfile::kLegacy;
  std::uint32_t columns_per_frame = 0;
  std::uint32_t columns_per_packet = 16;
  std::uint32_t pixels_per_column = 0;
  std::pair<std::uint32_t, std::uint32_t> column_window{0, 0};  ///< first and last column sent, inclusive
  std::vector<int> pixel_shift_by_row;          ///< one per row [columns]
  std::vector<double> beam_altitude_angles;     ///< [deg] one per row
  std::vector<double> beam_azimuth_angles;      ///< [deg] one per row
  double lidar_origin_to_beam_origin_mm = 0.0;
  Eigen::Matrix4d beam_to_lidar = Eigen::Matrix4d::Identity();    ///< [mm]
  Eigen::Matrix4d lidar_to_sensor = Eigen::Matrix4d::Identity();  ///< [mm]
  std::uint16_t udp_port_lidar = 7502;
  std::uint16_t udp_port_imu = 7503;
  bool nested_layout = false;  ///< the file had the newer nested layout

  /// Lidar packets a full sweep takes (the column window's columns / columns_per_packet, rounded up).
  [[nodiscard]] std::uint32_t packets_per_frame() const;
};

/// Parses metadata JSON text; `file` names it in errors. InputError for
/// text that is not JSON, a missing or mistyped key the decoder needs,
/// beam angle or pixel shift lists of another length than
/// pixels_per_column, an unknown udp_profile_lidar, or sizes out of range
/// (columns_per_frame 1..4096, a multiple of columns_per_packet 1..64;
/// pixels_per_column 1..256).
OusterMetadata parse_ouster_metadata(std::string_view json_text, const std::filesystem::path& file);

/// Reads and parses a metadata file.
OusterMetadata read_ouster_metadata(const std::filesystem::path& file);

}  // namespace saloam
