#pragma once
// A recorded sequence of LiDAR scans in any of the formats saloam reads,
// behind one interface: what a run needs (the scans in order, their
// timestamps, the calibration and reference poses when the source has them)
// and what `saloam info` shows. The formats:
//   semantickitti  SEQ/velodyne/NNNNNN.bin (+ labels/, times.txt, poses.txt, calib.txt)
//   kitti-raw      DRIVE/velodyne_points/data/*.bin + timestamps, oxts/ (GPS/INS reference)
//   pcd, ply       a folder of .pcd or .ply files (or one file), ordered by name
//   rosbag         a ROS 1 bag's sensor_msgs/PointCloud2 messages on one topic
// Module `sources` sits on `io` (which parses single files) and is what a
// run's FrameSource wraps; it keeps the multi-file layouts, the format
// detection and the ROS libraries out of io and out of the algorithms.
//
// Frames and units: scans are in the LiDAR frame, metres. Times are seconds:
// SemanticKITTI and PCD/PLY folders as their times.txt says (else as below),
// KITTI raw since the drive's first scan (as KITTI odometry's times.txt for
// the same drives), bags the messages' header stamps (since the epoch).
// Reference poses are those of poses.txt: KITTI camera-frame poses when
// velo_to_cam() is known (P_i = Tr Q_i Tr^-1), else LiDAR-frame poses
// T_L0<-Li (a source without calibration runs in the LiDAR frame).

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

enum class ScanFormat { kAuto, kSemanticKitti, kKittiRaw, kPcd, kPly, kRosbag };

/// "auto", "semantickitti", "kitti-raw", "pcd", "ply", "rosbag".
[[nodiscard]] std::string_view format_name(ScanFormat format);
/// The format of a --format value, nullopt for an unknown name.
[[nodiscard]] std::optional<ScanFormat> scan_format_from_name(std::string_view name);
/// Every --format value, for option checks and help texts.
[[nodiscard]] const std::vector<std::string>& scan_format_names();

struct ScanSequenceOptions {
  ScanFormat format = ScanFormat::kAuto;
  /// Folder of .label files named like the scans (their stems), instead of
  /// the source's own labels/ folder.
  std::optional<std::filesystem::path> labels_dir;
  /// Ignore labels entirely (label-agnostic runs).
  bool ignore_labels = false;
  /// The bag topic to read; empty: the only PointCloud2 topic of the bag.
  std::string topic;
};

/// What `saloam info` lists about a source beyond its scans (cheap: read
/// when the source is opened, no scan loaded).
struct ScanSequenceFacts {
  std::vector<std::string> notes;  ///< "times: times.txt", "reference: oxts/ (GPS/INS) via calib_imu_to_velo.txt", ...
};

class ScanSequence {
 public:
  virtual ~ScanSequence() = default;

  [[nodiscard]] virtual ScanFormat format() const = 0;
  /// The folder or file it reads.
  [[nodiscard]] virtual const std::filesystem::path& path() const = 0;
  /// For messages: the path, and the topic of a bag.
  [[nodiscard]] virtual std::string name() const { return path().string(); }
  [[nodiscard]] virtual std::size_t size() const = 0;
  /// One timestamp per scan, increasing.
  [[nodiscard]] virtual const std::vector<double>& times() const = 0;
  [[nodiscard]] virtual bool has_labels() const { return false; }
  /// Scan i (0 <= i < size()), in the LiDAR frame, with the optional ring
  /// and time fields the source has. InputError naming the file for a
  /// corrupt scan. Not safe to call from several threads at once.
  virtual LabelledCloud scan(std::size_t i) = 0;

  /// Tr (velodyne to camera 0), when the source has one (calib.txt).
  [[nodiscard]] virtual std::optional<Pose> velo_to_cam() const { return std::nullopt; }
  /// Reference poses, one per scan, in poses.txt's convention (see above).
  [[nodiscard]] virtual std::optional<std::vector<Pose>> reference_poses() const { return std::nullopt; }
  /// The point fields of the scans read so far, as the source names them
  /// ("x y z intensity ring t"); KITTI .bin scans: "x y z remission".
  [[nodiscard]] virtual std::string fields() const { return "x y z remission"; }
  /// Where the reference, the times and the calibration come from.
  [[nodiscard]] virtual ScanSequenceFacts facts() const { return {}; }
};

/// The format of `path` by what it holds: a file starting with the bag magic
/// "#ROSBAG V2.0" or named *.bag: rosbag; a .pcd or .ply file: that format;
/// a folder with velodyne/*.bin: semantickitti; with velodyne_points/data:
/// kitti-raw; with .pcd or .ply files: that format. InputError naming the
/// path and listing what was looked for when nothing matches (or both .pcd
/// and .ply files lie in one folder).
ScanFormat detect_scan_format(const std::filesystem::path& path);

/// Opens `path` as `options.format` (detected when kAuto). InputError for a
/// missing path, a layout that is not that format, or (for rosbag) a build
/// without rosbag_storage.
std::unique_ptr<ScanSequence> open_scan_sequence(const std::filesystem::path& path,
                                                 const ScanSequenceOptions& options = {});

}  // namespace saloam
