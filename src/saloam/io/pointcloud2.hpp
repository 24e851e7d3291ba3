#pragma once
// ROS 1 sensor_msgs/PointCloud2 messages in their serialised form (as a bag
// stores them; ROS 1 serialisation is little-endian, strings and arrays
// prefixed by a uint32 length):
//   std_msgs/Header header   uint32 seq, time stamp (uint32 sec, uint32 nsec), string frame_id
//   uint32 height, uint32 width
//   PointField[] fields      string name, uint32 offset, uint8 datatype (1 int8 .. 8 float64), uint32 count
//   bool is_bigendian, uint32 point_step, uint32 row_step
//   uint8[] data, bool is_dense
// The point fields become a LabelledCloud as point_fields.hpp says; fields
// of an unknown datatype are skipped. Parsed here, not through Debian's
// libsensor-msgs-dev, so that the bytes of a message are checked (offsets
// inside point_step, rows inside data) before any is used, and fuzzed.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/io/point_fields.hpp"

namespace saloam {

/// "sensor_msgs/PointCloud2" and its MD5 sum, as a bag's connection records name it.
inline constexpr std::string_view kPointCloud2Type = "sensor_msgs/PointCloud2";
inline constexpr std::string_view kPointCloud2Md5 = "1158d486dd51d683ce2f1be655c3c181";
/// The message definition (gendeps --cat), which a bag's connection stores.
extern const char* const kPointCloud2Definition;

struct RosHeader {
  std::uint32_t seq = 0;
  double stamp = 0.0;  ///< seconds since the epoch
  std::string frame_id;
};

struct PointCloud2Scan {
  RosHeader header;
  std::size_t width = 0, height = 0;
  DecodedCloud decoded;
};

/// Only the message's header (cheap: the stamp of every message of a bag).
/// InputError naming `file`, the problem prefixed by `context` ("topic /points, message 3").
RosHeader parse_ros_header(std::span<const std::byte> message, const std::filesystem::path& file,
                           std::string_view context);
/// The whole message; absolute per-point times are taken relative to the
/// header's stamp. InputError (file, context) for a message that is cut off,
/// or whose fields, steps and data do not fit together.
PointCloud2Scan parse_pointcloud2(std::span<const std::byte> message, const std::filesystem::path& file,
                                  std::string_view context);
/// `cloud` as a serialised PointCloud2 (height 1, little-endian, float32
/// x y z intensity, uint16 ring and float32 time when the cloud has them).
std::vector<std::byte> serialize_pointcloud2(const LabelledCloud& cloud, double stamp, std::string_view frame_id,
                                             std::uint32_t seq = 0);

}  // namespace saloam
