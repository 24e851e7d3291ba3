#pragma once
// A sequence directory in the SemanticKITTI layout:
//   velodyne/NNNNNN.bin  labels/NNNNNN.label  poses.txt  calib.txt  times.txt
// Labels may instead come from a separate predictions folder (as
// segmentation networks write them: NNNNNN.label, or sequences/XX/predictions/).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/io/scan_io.hpp"

namespace saloam {

struct SequenceOptions {
  /// Folder of .label files to use instead of `labels/` (e.g. network predictions).
  std::optional<std::filesystem::path> labels_dir;
  /// Ignore labels entirely (label-agnostic runs).
  bool ignore_labels = false;
};

class SequenceReader {
 public:
  /// Indexes the folder: scan i is velodyne/i.bin (NNNNNN.bin, numbered from
  /// 000000). Throws InputError when `velodyne/` is missing or empty, when a
  /// scan number is missing (a gap would pair later scans with the wrong pose
  /// and time), when an entry named like a scan is not a file or not a number,
  /// when a given labels folder does not exist, or when times.txt / poses.txt
  /// hold fewer lines than there are scans. More lines are accepted and the
  /// first ones used: a sequence folder may hold only the first scans.
  explicit SequenceReader(std::filesystem::path root, SequenceOptions options = {});

  [[nodiscard]] const std::filesystem::path& root() const { return root_; }
  [[nodiscard]] std::size_t size() const { return scan_files_.size(); }
  [[nodiscard]] bool has_labels() const { return labels_available_; }

  /// Loads scan i (velodyne/i.bin) with its labels when present.
  LabelledCloud load_scan(std::size_t index, ScanReadStats* stats = nullptr) const;
  [[nodiscard]] const std::filesystem::path& scan_file(std::size_t index) const { return scan_files_.at(index); }

  /// Timestamps from times.txt, or index * 0.1 s when the file is missing.
  [[nodiscard]] const std::vector<double>& times() const { return times_; }
  [[nodiscard]] bool has_times_file() const { return has_times_file_; }

  /// Velodyne-to-camera extrinsic Tr; throws InputError if calib.txt is missing
  /// (needed to convert between camera and LiDAR poses).
  [[nodiscard]] Pose velo_to_cam() const;
  [[nodiscard]] bool has_calib() const;

  /// Ground truth from poses.txt (camera frame, as in KITTI), if present.
  [[nodiscard]] bool has_poses() const { return !camera_poses_.empty(); }
  [[nodiscard]] const std::vector<Pose>& camera_poses() const { return camera_poses_; }
  /// Ground truth in the LiDAR frame (T_L0<-Li); throws InputError without
  /// poses.txt or calib.txt.
  [[nodiscard]] std::vector<Pose> lidar_poses() const;

 private:
  std::filesystem::path root_;
  SequenceOptions options_;
  std::vector<std::filesystem::path> scan_files_;
  std::vector<std::optional<std::filesystem::path>> label_files_;
  bool labels_available_ = false;
  std::vector<double> times_;
  bool has_times_file_ = false;
  std::vector<Pose> camera_poses_;
};

/// Writes a sequence folder; scans are numbered from 000000.
class SequenceWriter {
 public:
  explicit SequenceWriter(std::filesystem::path root);
  [[nodiscard]] const std::filesystem::path& root() const { return root_; }
  /// Writes velodyne/NNNNNN.bin and, when the cloud has labels, labels/NNNNNN.label.
  void write_scan(std::size_t index, const LabelledCloud& cloud) const;
  void write_camera_poses(const std::vector<Pose>& camera_poses) const;
  void write_calib(const Pose& velo_to_cam) const;
  void write_times(const std::vector<double>& times) const;

 private:
  std::filesystem::path root_;
};

/// "000042"
std::string frame_name(std::size_t index);

}  // namespace saloam
