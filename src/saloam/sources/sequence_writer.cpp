#include "saloam/sources/sequence_writer.hpp"

#include <cmath>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/db3.hpp"
#include "saloam/io/pointcloud2.hpp"
#include "saloam/io/rosbag2_metadata.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

void check_new_folder(const FrameSource& in, const fs::path& out) {
  std::error_code ec;
  if (fs::exists(out, ec)) {
    if (!fs::is_directory(out, ec) || !fs::is_empty(out, ec)) {
      throw InputError(out, "exists and is not an empty folder: write a sequence into a new folder");
    }
  }
  if (in.info().folder && fs::equivalent(*in.info().folder, out, ec)) throw InputError(out, "is the input: write a sequence into a new folder");
  create_folder(out);
}

/// The reference poses in the LiDAR frame, when the source has them.
std::optional<std::vector<Pose>> lidar_reference(const FrameSource& in) {
  const SourceInfo& info = in.info();
  if (!info.camera_poses) return std::nullopt;
  if (info.velo_to_cam) return camera_to_lidar_poses(*info.camera_poses, *info.velo_to_cam);
  return info.camera_poses;
}

void write_folder_extras(const FrameSource& in, const fs::path& out) {
  const SourceInfo& info = in.info();
  write_times(out / "times.txt", info.times);
  if (info.camera_poses) write_kitti_poses(out / "poses.txt", *info.camera_poses);
  if (info.velo_to_cam) write_calib(out / "calib.txt", *info.velo_to_cam);
}

void write_semantic_kitti(FrameSource& in, const fs::path& out) {
  const SequenceWriter writer(out);
  for (std::size_t i = 0; i < in.size(); ++i) writer.write_scan(i, in.scan(i));
  write_folder_extras(in, out);
}

void write_point_cloud_folder(FrameSource& in, const fs::path& out, const SequenceWriteOptions& options) {
  const bool ply = options.format == ScanFormat::kPly;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const LabelledCloud cloud = in.scan(i);
    const fs::path file = out / (frame_name(i) + (ply ? ".ply" : ".pcd"));
    if (ply) {
      write_ply_scan(file, cloud, options.ply);
    } else {
      write_pcd(file, cloud, options.pcd);
    }
    if (cloud.has_labels) write_scan_labels(out / "labels" / (frame_name(i) + ".label"), cloud);
  }
  write_folder_extras(in, out);
}

void write_kitti_raw(FrameSource& in, const fs::path& out) {
  const auto lidar = lidar_reference(in);
  if (!lidar) throw InputError(out, "a KITTI raw drive needs reference poses (oxts), and the source has none");
  const fs::path data = out / "velodyne_points" / "data";
  for (std::size_t i = 0; i < in.size(); ++i) write_scan_bin(data / fmt::format("{:010d}.bin", i), in.scan(i));
  // Nanoseconds after an epoch of whole seconds: relative times come back exactly as they were.
  std::vector<std::int64_t> stamps;
  for (const double t : in.info().times) {
    const auto epoch = static_cast<std::int64_t>(kKittiRawEpoch) * kNanosPerSecond;
    stamps.push_back(std::llround(t * 1e9) + (t < kAbsoluteTimeThreshold ? epoch : 0));
  }
  write_kitti_timestamps_ns(out / "velodyne_points" / "timestamps.txt", stamps);
  write_kitti_timestamps_ns(out / "oxts" / "timestamps.txt", stamps);
  const Pose velo_imu = kitti_imu_to_velo();
  std::vector<Pose> imu(lidar->size());
  const Pose first_inv = lidar->front().inverse();  // the reference starts at the identity
  for (std::size_t i = 0; i < imu.size(); ++i) imu[i] = velo_imu.inverse() * first_inv * (*lidar)[i] * velo_imu;
  const auto records = poses_to_oxts(imu, kitti_raw_origin());
  for (std::size_t i = 0; i < records.size(); ++i) write_oxts(out / "oxts" / "data" / fmt::format("{:010d}.txt", i), records[i]);
  write_imu_to_velo(out / "calib_imu_to_velo.txt", velo_imu);
}

void write_bag(FrameSource& in, const fs::path& out, const SequenceWriteOptions& options) {
  PointCloud2BagWriter writer(out, options.topic, options.frame_id, options.bag_compression);
  for (std::size_t i = 0; i < in.size(); ++i) writer.write(in.scan(i), in.info().times[i]);
  writer.close();
}

std::int64_t stamp_ns(double stamp) { return std::llround(stamp * 1e9); }

void write_rosbag2(FrameSource& in, const fs::path& out, const SequenceWriteOptions& options) {
  // Named after the folder, as rosbag2 names its files ("bag/" has no filename: its parent's name).
  const fs::path folder = out.has_filename() ? out.filename() : out.parent_path().filename();
  const std::string stem = folder.empty() || folder == "." || folder == ".." ? std::string("rosbag2") : folder.string();
  const std::string name = stem + "_0.db3";
  Db3Writer db(out / name);
  const std::int64_t topic = db.add_topic(options.topic, std::string(kRos2PointCloud2Type));
  const auto& times = in.info().times;
  for (std::size_t i = 0; i < in.size(); ++i) {
    db.write(topic, stamp_ns(times[i]), serialize_pointcloud2_cdr(in.scan(i), times[i], options.frame_id, options.cdr_big_endian));
  }
  const StoredTopic stored{options.topic, std::string(kRos2PointCloud2Type), "cdr", in.size()};
  const Rosbag2FileSummary file{name, in.size() ? stamp_ns(times.front()) : 0, in.size() ? stamp_ns(times.back()) : 0, in.size()};
  const std::string metadata = rosbag2_metadata_text("sqlite3", {stored}, file);
  db.close(metadata);
  write_file_atomically(out / "metadata.yaml", metadata);
}

void write_mcap(FrameSource& in, const fs::path& out, const SequenceWriteOptions& options) {
  McapWriter mcap(out, options.mcap_compression, options.mcap_chunk_bytes);
  const auto schema = mcap.add_schema(std::string(kRos2PointCloud2Type), "ros2msg", kRos2PointCloud2Definition);
  const auto channel = mcap.add_channel(options.topic, schema, "cdr");
  const auto& times = in.info().times;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const auto message = serialize_pointcloud2_cdr(in.scan(i), times[i], options.frame_id, options.cdr_big_endian);
    mcap.write(channel, static_cast<std::uint64_t>(std::max<std::int64_t>(stamp_ns(times[i]), 0)), message);
  }
  mcap.close();
}

}  // namespace

OxtsRecord kitti_raw_origin() {
  OxtsRecord r;
  r.lat = 49.011;
  r.lon = 8.4236;
  r.alt = 112.0;
  r.yaw = 60.0 * 3.14159265358979323846 / 180.0;
  return r;
}

Pose kitti_imu_to_velo() {
  Pose T = Pose::Identity();
  T.linear() << 9.999976e-01, 7.553071e-04, -2.035826e-03, -7.854027e-04, 9.998898e-01, -1.482298e-02, 2.024406e-03,
      1.482454e-02, 9.998881e-01;
  T.translation() << -8.086759e-01, 3.195559e-01, -7.997231e-01;
  return orthonormalized(T);
}

void write_scan_sequence(FrameSource& in, const fs::path& out, const SequenceWriteOptions& options) {
  if (options.format == ScanFormat::kRosbag || options.format == ScanFormat::kMcap) {
    std::error_code ec;
    if (fs::exists(out, ec)) throw InputError(out, "exists: write a bag into a new file");
    create_parent_folder(out);
    return options.format == ScanFormat::kMcap ? write_mcap(in, out, options) : write_bag(in, out, options);
  }
  if (options.format == ScanFormat::kAuto) throw InputError(out, "name the layout to write (auto is not one)");
  check_new_folder(in, out);
  switch (options.format) {
    case ScanFormat::kSemanticKitti: return write_semantic_kitti(in, out);
    case ScanFormat::kPcd:
    case ScanFormat::kPly: return write_point_cloud_folder(in, out, options);
    case ScanFormat::kKittiRaw: return write_kitti_raw(in, out);
    case ScanFormat::kRosbag2: return write_rosbag2(in, out, options);
    default: break;
  }
}

}  // namespace saloam
