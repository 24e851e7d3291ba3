#pragma once
// Writes a scan sequence in any layout saloam reads (source_options.hpp), from
// any FrameSource: the simulator's SemanticKITTI output into PCD, PLY, KITTI
// raw or a bag, a real drive into another layout. What each layout keeps:
//   semantickitti  velodyne/*.bin, labels/ (when labelled), times.txt,
//                  poses.txt and calib.txt (when the source has them)
//   pcd, ply       NNNNNN.pcd|ply (x y z intensity [ring] [time]), labels/,
//                  times.txt, poses.txt, calib.txt
//   kitti-raw      velodyne_points/data/NNNNNNNNNN.bin, timestamps.txt (times
//                  below 1e5 s are put after kKittiRawEpoch), oxts/data/ from
//                  the reference poses in the LiDAR frame through
//                  kitti_imu_to_velo() and kKittiRawOrigin, calib_imu_to_velo.txt
//   rosbag         PointCloud2 messages on `topic` stamped with the times
//   rosbag2        a folder: metadata.yaml and NAME_0.db3 (NAME: the
//                  folder's name) holding sensor_msgs/msg/PointCloud2
//                  messages (CDR) on `topic`, stamped with the times (log
//                  time: the stamp in ns)
//   mcap           one file, the same messages in zstd (or lz4, or
//                  uncompressed) chunks of about 1 MiB, indexed, with a summary
// Per-point rings and times survive pcd, ply and the bags; labels survive
// semantickitti, pcd and ply.

#include <filesystem>
#include <string>

#include "saloam/io/kitti_raw.hpp"
#include "saloam/io/mcap.hpp"
#include "saloam/io/pcd.hpp"
#include "saloam/io/ply.hpp"
#include "saloam/io/frame_source.hpp"
#include "saloam/sources/rosbag_source.hpp"
#include "saloam/sources/source_options.hpp"

namespace saloam {

struct SequenceWriteOptions {
  ScanFormat format = ScanFormat::kSemanticKitti;
  PcdEncoding pcd = PcdEncoding::kBinary;
  PlyEncoding ply = PlyEncoding::kBinaryLittleEndian;
  std::string topic = "/points";
  std::string frame_id = "velodyne";
  BagCompression bag_compression = BagCompression::kLz4;
  McapCompression mcap_compression = McapCompression::kZstd;
  std::size_t mcap_chunk_bytes = 1u << 20;
  bool cdr_big_endian = false;  ///< ROS 2 messages in big-endian CDR (as some non-x86 hosts record)
};

/// 2011-09-26 13:02:25 UTC, the first scan of KITTI raw drive 0005 [s since the epoch].
inline constexpr double kKittiRawEpoch = 1317042145.0;
/// Where written oxts records start: a point in Karlsruhe, where KITTI drove
/// (49.011 N, 8.4236 E, 112 m, heading 60 deg from east).
OxtsRecord kitti_raw_origin();
/// KITTI's 2011_09_26 calib_imu_to_velo (T_velo<-imu).
Pose kitti_imu_to_velo();

/// Writes every scan of `in` and what goes with it (times, reference poses,
/// Tr) into `out`, which must not exist yet or be an empty folder (an input
/// is never overwritten; a bag or MCAP file: must not exist).
/// InputError naming `out` otherwise, or for a layout that cannot hold the
/// source (kitti-raw needs reference poses; kAuto is no layout).
void write_scan_sequence(FrameSource& in, const std::filesystem::path& out, const SequenceWriteOptions& options);

}  // namespace saloam
