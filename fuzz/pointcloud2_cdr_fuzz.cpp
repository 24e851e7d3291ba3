// Serialised ROS 2 sensor_msgs/msg/PointCloud2 messages in CDR
// (parse_pointcloud2_cdr), as .db3 and .mcap files hold them, in either
// byte order; the header alone (parse_ros2_header) must agree.

#include "point_cloud_checks.hpp"
#include "saloam/io/pointcloud2.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  const std::filesystem::path file = "scans.mcap";
  const auto bytes = fuzz::as_bytes(data, size);
  try {
    const PointCloud2Scan scan = parse_pointcloud2_cdr(bytes, file, "topic /points, message 0");
    fuzz::check_decoded_cloud(scan.decoded);
    SALOAM_FUZZ_CHECK(scan.decoded.points_in_file == scan.width * scan.height);
    const RosHeader header = parse_ros2_header(bytes, file, "topic /points, message 0");
    SALOAM_FUZZ_CHECK(header.stamp == scan.header.stamp && header.frame_id == scan.header.frame_id);
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
