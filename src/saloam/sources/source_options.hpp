#pragma once
// What a command asks of a source: the layout to read it as, the bag topic,
// labels, calibration, the intensity range, the frame range and the
// segmentation stage. Shared by open_reader() and the readers
// (sources/*.hpp); the commands fill it from cli::SourceArgs (SEQ_DIR,
// --format, --topic, --labels, --frames, --no-calib, --intensity-scale).
//
// The layouts (--format):
//   semantickitti  SEQ/velodyne/NNNNNN.bin (+ labels/, times.txt, poses.txt, calib.txt)
//   kitti-raw      DRIVE/velodyne_points/data/*.bin + timestamps, oxts/ (GPS/INS reference)
//   pcd, ply       a folder of .pcd or .ply files (or one file), ordered by name
//   rosbag         a ROS 1 bag's sensor_msgs/PointCloud2 messages on one topic
//   rosbag2        a ROS 2 bag's: a folder with metadata.yaml and .db3 (or
//                  .mcap) files, or one .db3 file
//   mcap           an MCAP file's (ROS 2 messages, CDR)
//   pcap           a sensor's packet capture: Ouster (with its metadata JSON)
//                  or Velodyne VLP-16 / HDL-32E / HDL-64E (sources/pcap_source.hpp)
//   auto           detected from the path (detect_scan_format)
// A path `udp://[ADDRESS]:PORT` is no layout but a live source: a sensor's
// UDP packets as they arrive (sources/live_udp_source.hpp, LiveOptions).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/frame_range.hpp"
#include "saloam/segmentation/segmented_source.hpp"

namespace saloam {

enum class ScanFormat { kAuto, kSemanticKitti, kKittiRaw, kPcd, kPly, kRosbag, kRosbag2, kMcap, kPcap };

/// "auto", "semantickitti", "kitti-raw", "pcd", "ply", "rosbag", "rosbag2", "mcap", "pcap".
[[nodiscard]] std::string_view format_name(ScanFormat format);
/// The format of a --format value, nullopt for an unknown name.
[[nodiscard]] std::optional<ScanFormat> scan_format_from_name(std::string_view name);
/// Every --format value, for option checks and help texts.
[[nodiscard]] const std::vector<std::string>& scan_format_names();

/// What a live source (udp://) needs besides the address.
struct LiveOptions {
  /// --sensor: whose packets arrive: vlp16, hdl32e, hdl64e (Velodyne), or
  /// an Ouster (os1-64, os1-128, or any name with --metadata META.json).
  std::string sensor;
  /// --idle-timeout [s]: the stream ends when no packet arrived for this
  /// long (from the start too); 0: never (only Ctrl-C or a frame limit end it).
  double idle_timeout_s = 10.0;
  /// --queue: frames held for a run that falls behind; beyond, the oldest
  /// whole frame is dropped (and counted).
  std::size_t queue_frames = 4;
  /// Receive buffer asked for [bytes], past net.core.rmem_max as root (the log warns when the kernel grants less).
  int receive_buffer_bytes = 64 << 20;
};

struct SourceOptions {
  ScanFormat format = ScanFormat::kAuto;  ///< --format
  /// --topic: the bag topic to read; empty: the only PointCloud2 topic of the bag.
  std::string topic;
  /// --metadata: an Ouster capture's metadata JSON, or a Velodyne
  /// calibration YAML; none: looked for beside the capture (pcap_source.hpp).
  std::optional<std::filesystem::path> metadata;
  /// --labels: .label files from this folder (named like the scans) instead
  /// of the source's own labels/.
  std::optional<std::filesystem::path> labels;
  /// Frames without labels (--no-semantics, label-agnostic loop detectors).
  bool ignore_labels = false;
  /// --no-calib: calib.txt is not read; the run works in the LiDAR frame
  /// (pose files hold LiDAR-frame poses, poses.txt is taken as such). A
  /// source without calib.txt runs so anyway.
  bool ignore_calib = false;
  /// --intensity-scale: what the file's intensity values are divided by to
  /// make remission 0..1 (1, 255 or 65535); none: each reader decides from
  /// the field's type or its first scan (io/intensity_scale.hpp).
  std::optional<float> intensity_scale;
  FrameRange frames;  ///< --frames A:B; everything by default
  LiveOptions live;  ///< a udp:// source's
  /// The sensor profile's laser count (--sensor, or guessed): points with a
  /// ring at or beyond it are dropped and counted (SensorRingsSource); 0: no profile.
  std::size_t sensor_lasers = 0;
  /// --segment: every scan labelled by this model (the reader's labels are not read).
  std::optional<SegmentationStageOptions> segmentation;
};

}  // namespace saloam
