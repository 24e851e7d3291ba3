#pragma once
// Velodyne VLP-16, HDL-32E and HDL-64E (S2/S3) data packets, bytes in,
// points out (and the inverse, for the simulator's captures): pure
// functions, no I/O. The 1206-byte UDP payload (port 2368) is 12 blocks of
// 100 bytes and a 6-byte tail:
//   block   flag u16 (0xEEFF: upper block, lasers 0-31; 0xDDFF: HDL-64E's
//           lower block, lasers 32-63), azimuth u16 [0.01 deg], then 32 x
//           (distance u16 [2 mm; 0 = no return], intensity u8)
//   tail    timestamp u32 [us past the hour], then on VLP-16 and HDL-32E
//           the return mode (0x37 strongest, 0x38 last, 0x39 dual) and the
//           product id (0x21 HDL-32E, 0x22 VLP-16); on the HDL-64E a status
//           byte pair instead (single return read)
// all little-endian. Distances are 2 mm units on all three models (the
// manuals' "distance resolution 0.2 cm").
//
// Geometry: the ROS velodyne_pointcloud calibration (db.xml's fields,
// velodyne_pointcloud's YAML: per laser rot_correction and vert_correction
// [rad], dist_correction, dist_correction_x/_y, vert_offset_correction,
// horiz_offset_correction [m]) as velodyne_pointcloud applies it (its
// RawData::unpack): with the block's azimuth a (clockwise seen from above,
// 0 = forward) less rot_correction, distance d = raw * 0.002 +
// dist_correction, elevation v,
//   x = d cos v cos a (+ offsets), y = -d cos v sin a, z = d sin v + vert_offset cos v,
// the two-point distance correction in x and y included. Points are in the
// sensor frame [m]: x forward, y left, z up.
//
// Timing (the manuals' firing sequences), each point's offset from the
// packet's timestamp:
//   VLP-16   a block holds two firing sequences of the 16 lasers; lasers
//            2.304 us apart, sequences 55.296 us, blocks 110.592 us; each
//            laser's azimuth is interpolated between the block's and the
//            next block's by its firing time (as velodyne_pointcloud does)
//   HDL-32E  one firing of the 32 lasers per block, in pairs 1.152 us apart,
//            blocks 46.08 us apart; every laser at the block's azimuth
//   HDL-64E  an upper and a lower block fire together, 48 us per pair of
//            blocks (the S2 manual's packet rate), the 32 lasers of a block
//            1.5 us apart (Velodyne documents no per-laser sequence for it);
//            every laser at the block's azimuth
// Dual return (0x39): blocks come in pairs of one firing (last return,
// then strongest or second strongest); the last returns are kept.
// Rings: 0 is the laser of the highest elevation.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace saloam {

inline constexpr std::size_t kVelodynePacketBytes = 1206;
inline constexpr std::uint16_t kVelodyneDataPort = 2368;
inline constexpr double kVelodyneDistanceUnit = 0.002;  ///< [m] per distance count

enum class VelodyneModel { kVlp16, kHdl32e, kHdl64e };
enum class VelodyneReturnMode : std::uint8_t { kStrongest = 0x37, kLast = 0x38, kDual = 0x39 };

[[nodiscard]] std::string_view velodyne_model_name(VelodyneModel model);  ///< "VLP-16", ...
[[nodiscard]] std::size_t velodyne_lasers(VelodyneModel model);           ///< 16, 32, 64

struct VelodyneLaser {
  double rot_correction = 0.0;   ///< [rad]
  double vert_correction = 0.0;  ///< [rad] elevation
  double dist_correction = 0.0;  ///< [m]
  double dist_correction_x = 0.0;
  double dist_correction_y = 0.0;
  double vert_offset = 0.0;   ///< [m] vert_offset_correction
  double horiz_offset = 0.0;  ///< [m] horiz_offset_correction
};

struct VelodyneCalibration {
  std::vector<VelodyneLaser> lasers;  ///< by laser id
  std::string source;                 ///< "built-in VLP-16 angles", or the file
};

/// The datasheet's laser elevations of a VLP-16 or HDL-32E, no offsets
/// (an HDL-64E has no nominal table: each unit has its own calibration).
[[nodiscard]] std::optional<VelodyneCalibration> nominal_velodyne_calibration(VelodyneModel model);
/// A velodyne_pointcloud calibration YAML (num_lasers, lasers: [{laser_id,
/// rot_correction, vert_correction, dist_correction, ...}]); missing
/// corrections are 0 (dist_correction_x/_y: dist_correction). InputError
/// naming `file` for YAML that is not one, a laser id out of range or twice,
/// or a laser missing.
[[nodiscard]] VelodyneCalibration parse_velodyne_calibration(std::string_view yaml_text, const std::filesystem::path& file);
[[nodiscard]] VelodyneCalibration read_velodyne_calibration(const std::filesystem::path& file);
/// The calibration as such a YAML file.
[[nodiscard]] std::string velodyne_calibration_yaml(const VelodyneCalibration& calibration);

/// One return.
struct VelodyneReturn {
  Eigen::Vector3f point;      ///< [m] sensor frame
  float intensity = 0.0F;     ///< 0..255 as sent
  std::uint16_t ring = 0;     ///< 0 = highest laser
  std::uint16_t block = 0;    ///< block of the packet (0..11)
  double time_offset = 0.0;   ///< [s] after the packet's timestamp
};

/// What a packet's tail says.
struct VelodyneTail {
  std::uint32_t timestamp_us = 0;  ///< past the hour
  std::uint8_t byte_1204 = 0;      ///< return mode (VLP-16, HDL-32E) or HDL-64E status type
  std::uint8_t byte_1205 = 0;      ///< product id (VLP-16 0x22, HDL-32E 0x21) or HDL-64E status value
};

/// Empty when `packet` is a data packet: 1206 bytes, every block flag
/// 0xEEFF (or 0xDDFF on an HDL-64E), azimuths below 36000; else why not.
[[nodiscard]] std::string check_velodyne_packet(std::span<const std::uint8_t> packet);
[[nodiscard]] VelodyneTail velodyne_tail(std::span<const std::uint8_t> packet);
/// Block b's azimuth [0.01 deg].
[[nodiscard]] std::uint16_t velodyne_block_azimuth(std::span<const std::uint8_t> packet, std::size_t block);
/// The model a packet comes from: its product id, else an HDL-64E when
/// it has lower blocks; nullopt when it cannot tell.
[[nodiscard]] std::optional<VelodyneModel> velodyne_model_of(std::span<const std::uint8_t> packet);

class VelodyneDecoder {
 public:
  /// InputError-free: the calibration must hold velodyne_lasers(model) lasers (std::invalid_argument).
  VelodyneDecoder(VelodyneModel model, VelodyneCalibration calibration);
  [[nodiscard]] VelodyneModel model() const { return model_; }
  [[nodiscard]] const VelodyneCalibration& calibration() const { return calibration_; }
  /// The returns of a packet that check_velodyne_packet accepts, block by
  /// block; distances of 0 (no return) left out.
  void decode(std::span<const std::uint8_t> packet, std::vector<VelodyneReturn>& out) const;
  /// Whether the packet holds dual returns (blocks in pairs).
  [[nodiscard]] bool dual(std::span<const std::uint8_t> packet) const;

 private:
  [[nodiscard]] Eigen::Vector3f place(std::size_t laser, double distance_m, double azimuth_rad) const;
  [[nodiscard]] double firing_offset_us(std::size_t block, std::size_t channel, bool dual) const;

  VelodyneModel model_;
  VelodyneCalibration calibration_;
  std::vector<std::uint16_t> ring_of_laser_;
  std::vector<double> cos_vert_, sin_vert_;
};

/// One firing of the lasers of a block (for writing packets): raw distance
/// [2 mm] and intensity per channel (32), at one azimuth.
struct VelodyneFiring {
  std::uint16_t azimuth = 0;  ///< [0.01 deg]
  bool lower = false;         ///< HDL-64E lower block (lasers 32-63)
  std::array<std::uint16_t, 32> distance{};
  std::array<std::uint8_t, 32> intensity{};
};

/// A single-return data packet of 12 blocks; `timestamp_us` past the hour.
/// VLP-16 blocks carry two firing sequences each: channels 0-15 and 16-31.
[[nodiscard]] std::vector<std::uint8_t> encode_velodyne_packet(VelodyneModel model,
                                                                std::span<const VelodyneFiring, 12> blocks,
                                                                std::uint32_t timestamp_us);

/// The time [us] of firing `block` of a single-return packet after its
/// timestamp (what decode() adds for the block's first laser).
[[nodiscard]] double velodyne_block_offset_us(VelodyneModel model, std::size_t block);

}  // namespace saloam
