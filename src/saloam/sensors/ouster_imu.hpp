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

/// The sample with both vectors rotated by `rotation` (e.g. imu_to_lidar_rotation()).
[[nodiscard]] ImuSample rotated(const ImuSample& sample, const Eigen::Matrix3d& rotation);

/// Below this gyroscope norm a sample counts as at rest: 0.1 rad/s (5.7 deg/s),
/// several times an Ouster gyroscope's noise (0.3-0.5 deg/s per axis on the
/// still captures of ../shared/data/ouster_pcaps, norms up to 1.8 deg/s).
inline constexpr double kImuRestGyroRadS = 0.1;

struct ImuStreamStats {
  std::size_t samples = 0;
  double rate_hz = 0.0;            ///< steps forward per second of them; 0 with fewer than 2 distinct times
  double median_period_s = 0.0;    ///< of the steps forward
  double largest_gap_s = 0.0;      ///< the longest step forward
  std::size_t backwards_steps = 0; ///< samples earlier than the one before
  std::size_t repeated_times = 0;  ///< samples at the same time as the one before
  std::size_t rest_samples = 0;    ///< gyroscope norm below kImuRestGyroRadS
  /// [m/s^2] mean |a| over the rest samples; NaN without any
  double gravity_at_rest = std::numeric_limits<double>::quiet_NaN();
  /// [deg/s] per-axis standard deviation (RMS over x, y, z) over the rest samples; NaN with under 2
  double gyro_noise_dps = std::numeric_limits<double>::quiet_NaN();
  double mean_acceleration_norm = 0.0;  ///< [m/s^2] mean |a| over all samples
  double largest_gyro_rad_s = 0.0;      ///< [rad/s] largest gyroscope norm
  double median_gyro_rad_s = 0.0;       ///< [rad/s] median gyroscope norm
  Eigen::Vector3d mean_acceleration = Eigen::Vector3d::Zero();  ///< [m/s^2] over all samples
};

[[nodiscard]] ImuStreamStats imu_stream_stats(const std::vector<ImuSample>& samples);

/// What looks wrong, one sentence each; empty when all is plausible: no
/// samples; |a| near 1 (g read as m/s^2) or far from gravity otherwise;
/// angular velocities over 20 rad/s, or never near 0 (deg/s read as rad/s);
/// time going backwards or repeating; a gap over 3 median periods.
[[nodiscard]] std::vector<std::string> imu_stream_problems(const ImuStreamStats& stats);

/// Up (unit, against gravity) in the frame `rotation` turns the samples into
/// (R_to<-imu, e.g. imu_to_lidar_rotation()): the direction of the mean
/// specific force over the samples at rest (kImuRestGyroRadS) among the
/// first kImuUpSamples, which at rest is gravity's reaction. Nothing with
/// fewer than 5 such samples or a mean magnitude more than kImuRestTolerance
/// from 1 g (the sensor was accelerating, or the units are wrong: the
/// moving OS1-128 capture of ../shared reads 1.089 g, its forward
/// acceleration or vibration tilting the mean 22 deg; the still ones
/// 1.011-1.029 g).
inline constexpr std::size_t kImuUpSamples = 200;
inline constexpr double kImuRestTolerance = 0.05;
[[nodiscard]] std::optional<Eigen::Vector3d> imu_up_at_rest(const std::vector<ImuSample>& samples,
                                                            const Eigen::Matrix3d& rotation);

}  // namespace saloam
