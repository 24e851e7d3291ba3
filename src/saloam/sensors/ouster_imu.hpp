#pragma once
// An Ouster sensor's own IMU: its UDP packets decoded, read from a capture,
// placed in the lidar frame, and checked for plausible units and timing.
//
// Packet layout (udp_profile_imu LEGACY, the profile every metadata file of
// ../shared/data/ouster_pcaps names or, before firmware 2.2, implies; Ouster's
// "Sensor Data" documentation, "IMU Data Format", and ouster-sdk's
// packet_format::imu_* accessors): one 48-byte UDP datagram per sample,
// little-endian:
//   bytes  0..7   uint64  system (diagnostic) time [ns]
//   bytes  8..15  uint64  accelerometer read time [ns]
//   bytes 16..23  uint64  gyroscope read time [ns]
//   bytes 24..35  float32 x3 linear acceleration x, y, z [g]
//   bytes 36..47  float32 x3 angular velocity x, y, z [deg/s]
// The times are the sensor's clock (its timestamp_mode: the internal
// oscillator since power-on, PTP or PPS), the clock of the lidar packets'
// column timestamps, not the capture's record times. The accelerometer reads
// specific force: at rest it points up with magnitude 1 g.
//
// Frames: a sample is in the IMU's own frame, as the packet gives it. The
// metadata's imu_to_sensor_transform and lidar_to_sensor_transform (4x4,
// row-major, translation [mm]) map points of the IMU and lidar frames into
// the sensor frame: p_sensor = T_imu_to_sensor p_imu = T_lidar_to_sensor
// p_lidar (ouster-ros publishes them as sensor -> imu and sensor -> lidar
// transforms). Hence R_lidar<-imu = R_lidar_to_sensor^T R_imu_to_sensor; on
// the OS0 / OS1 files here that is a rotation by 180 deg about z (x and y
// flip sign, z stays up). Rotating a sample needs no translation: angular
// velocity is the same at every point of a rigid body, and the lever arm's
// centripetal and tangential terms (the IMU sits a few cm from the lidar
// origin) are ignored, as they are small next to gravity.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "saloam/imu/imu_sample.hpp"
#include "saloam/imu/imu_stream.hpp"

namespace saloam {

inline constexpr std::size_t kOusterImuPacketBytes = 48;

/// The sample in a LEGACY IMU packet's payload: g -> m/s^2 (kStandardGravity),
/// deg/s -> rad/s, time from the accelerometer's read time (the sensor's
/// clock [s]), vectors in the IMU's frame. nullopt when the
/// payload is not kOusterImuPacketBytes long or a value is NaN or infinite.
[[nodiscard]] std::optional<ImuSample> decode_ouster_imu_packet(std::span<const std::byte> payload);

/// What read_ouster_imu passed over on the IMU port.
struct ImuReadCounts {
  std::size_t datagrams = 0;     ///< datagrams to the IMU port
  std::size_t wrong_size = 0;    ///< of another size than kOusterImuPacketBytes
  std::size_t non_finite = 0;    ///< with a NaN or infinite value
};

/// Every IMU sample in a capture: the datagrams sent to `imu_port`, in
/// capture order, those that do not decode skipped (and counted in `counts`
/// when given). InputError naming the file when it is not a capture.
[[nodiscard]] std::vector<ImuSample> read_ouster_imu(const std::filesystem::path& pcap, std::uint16_t imu_port,
                                                     ImuReadCounts* counts = nullptr);

/// What the metadata JSON says about the IMU, from either layout (flat:
/// top-level udp_port_imu, imu_to_sensor_transform, lidar_to_sensor_transform,
/// data_format/udp_profile_imu; nested: config_params/udp_port_imu,
/// imu_intrinsics/imu_to_sensor_transform, lidar_intrinsics/
/// lidar_to_sensor_transform, lidar_data_format/ or config_params/
/// udp_profile_imu). Note udp_dest is the host the sensor sends to, not a port.
struct OusterImuCalibration {
  std::uint16_t udp_port_imu = 7503;  ///< 7503 when the file has none (firmware before 2.2)
  Eigen::Matrix4d imu_to_sensor = Eigen::Matrix4d::Identity();    ///< [mm]
  Eigen::Matrix4d lidar_to_sensor = Eigen::Matrix4d::Identity();  ///< [mm]

  /// R_lidar<-imu = R_lidar_to_sensor^T R_imu_to_sensor.
  [[nodiscard]] Eigen::Matrix3d imu_to_lidar_rotation() const;
};

/// Parses metadata text; `file` names it in errors. InputError for text that
/// is not a JSON object, a missing transform, a transform whose rotation is
/// not one (|R^T R - I| > 1e-3 or det < 0) or whose last row is not 0 0 0 1,
/// a port outside 1..65535, or a udp_profile_imu other than LEGACY.
[[nodiscard]] OusterImuCalibration parse_ouster_imu_calibration(std::string_view json_text,
                                                                const std::filesystem::path& file);
/// Reads and parses a metadata file.
[[nodiscard]] OusterImuCalibration read_ouster_imu_calibration(const std::filesystem::path& file);


}  // namespace saloam
