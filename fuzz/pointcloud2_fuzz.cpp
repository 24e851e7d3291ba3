// Serialised ROS 1 sensor_msgs/PointCloud2 messages (parse_pointcloud2), as
// a bag holds them; the header alone (parse_ros_header) must agree.

#include "point_cloud_checks.hpp"
#include "saloam/io/pointcloud2.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  const std::filesystem::path file = "scans.bag";
  const auto bytes = fuzz::as_bytes(data, size);
  try {
    const PointCloud2Scan scan = parse_pointcloud2(bytes, file, "topic /points, message 0");
    fuzz::check_decoded_cloud(scan.decoded);
    SALOAM_FUZZ_CHECK(scan.decoded.points_in_file == scan.width * scan.height);
    const RosHeader header = parse_ros_header(bytes, file, "topic /points, message 0");
    SALOAM_FUZZ_CHECK(header.stamp == scan.header.stamp && header.frame_id == scan.header.frame_id);
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
