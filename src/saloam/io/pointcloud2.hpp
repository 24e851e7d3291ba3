#pragma once
// sensor_msgs/PointCloud2 messages in their serialised forms: ROS 1 (as a
// bag stores them; little-endian, strings and arrays prefixed by a uint32
// length) and ROS 2 (CDR, io/cdr.hpp: as rosbag2 .db3 and .mcap files store
// them; either byte order, aligned; the header has no seq and a signed
// second: builtin_interfaces/Time {int32 sec, uint32 nanosec}):
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
/// The ROS 2 type name, as rosbag2's topics table and MCAP schemas name it.
inline constexpr std::string_view kRos2PointCloud2Type = "sensor_msgs/msg/PointCloud2";
/// The ROS 2 message definition with its dependencies (MCAP schema encoding "ros2msg").
extern const char* const kRos2PointCloud2Definition;

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
/// ROS 2 (CDR) counterparts of the two above; RosHeader::seq is 0.
RosHeader parse_ros2_header(std::span<const std::byte> message, const std::filesystem::path& file,
                            std::string_view context);
PointCloud2Scan parse_pointcloud2_cdr(std::span<const std::byte> message, const std::filesystem::path& file,
                                      std::string_view context);
/// `cloud` as a serialised PointCloud2 (height 1, little-endian, float32
/// x y z intensity, uint16 ring and float32 time when the cloud has them).
std::vector<std::byte> serialize_pointcloud2(const LabelledCloud& cloud, double stamp, std::string_view frame_id,
                                             std::uint32_t seq = 0);
/// The same as a CDR message, in either byte order (header, lengths and the
/// point data; is_bigendian says which).
std::vector<std::byte> serialize_pointcloud2_cdr(const LabelledCloud& cloud, double stamp, std::string_view frame_id,
                                                 bool big_endian = false);

}  // namespace saloam
