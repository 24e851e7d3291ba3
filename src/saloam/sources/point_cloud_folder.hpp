#pragma once
// A folder of PCD or PLY scans (or one such file) as a ScanSequence.
//   FOLDER/*.pcd | *.ply   the scans, ordered as scan_files.hpp says
//   FOLDER/times.txt       optional: one timestamp per scan (seconds);
//                          else the file names' timestamps, else 0.1 s steps
//   FOLDER/poses.txt       optional: reference poses (KITTI 3x4 lines)
//   FOLDER/calib.txt       optional: Tr; without it, the LiDAR frame
//   FOLDER/labels/STEM.label, or ScanSequenceOptions::labels_dir
// Fields are read as point_fields.hpp says; absolute per-point times are
// taken relative to the scan's timestamp when that is a real time (from the
// file names, or a times.txt of times since the epoch).

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "saloam/sources/scan_sequence.hpp"

namespace saloam {

class PointCloudFolder final : public ScanSequence {
 public:
  /// `format` is kPcd or kPly; `path` a folder or one file of that format.
  PointCloudFolder(std::filesystem::path path, ScanFormat format, const ScanSequenceOptions& options);

  [[nodiscard]] ScanFormat format() const override { return format_; }
  [[nodiscard]] const std::filesystem::path& path() const override { return path_; }
  [[nodiscard]] std::size_t size() const override { return files_.size(); }
  [[nodiscard]] const std::vector<double>& times() const override { return times_; }
  [[nodiscard]] bool has_labels() const override { return !label_files_.empty(); }
  LabelledCloud scan(std::size_t i) override;
  [[nodiscard]] std::optional<Pose> velo_to_cam() const override { return velo_to_cam_; }
  [[nodiscard]] std::optional<std::vector<Pose>> reference_poses() const override { return poses_; }
  [[nodiscard]] ScanSequenceFacts facts() const override { return facts_; }

  [[nodiscard]] const std::filesystem::path& scan_file(std::size_t i) const { return files_.at(i); }
  [[nodiscard]] std::string fields() const override { return fields_; }

 private:
  void read_times(const std::optional<std::vector<double>>& name_stamps);
  void find_labels(const ScanSequenceOptions& options);

  std::filesystem::path path_;
  std::filesystem::path folder_;
  ScanFormat format_;
  std::vector<std::filesystem::path> files_;
  std::vector<std::filesystem::path> label_files_;  ///< empty, or one per scan
  std::vector<double> times_;
  bool stamps_are_absolute_ = false;
  std::optional<Pose> velo_to_cam_;
  std::optional<std::vector<Pose>> poses_;
  ScanSequenceFacts facts_;
  std::string fields_;
};

}  // namespace saloam
