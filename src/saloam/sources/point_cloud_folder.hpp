#pragma once
// A folder of PCD or PLY scans (or one such file) as a FrameSource.
//   FOLDER/*.pcd | *.ply   the scans, ordered as scan_files.hpp says
//   FOLDER/times.txt       optional: one timestamp per scan (seconds);
//                          else the file names' timestamps, else 0.1 s steps
//   FOLDER/poses.txt       optional: reference poses (KITTI 3x4 lines)
//   FOLDER/calib.txt       optional: Tr (unless --no-calib); without it, the
//                          LiDAR frame (poses.txt then holds LiDAR-frame poses)
//   FOLDER/labels/STEM.label, or SourceOptions::labels
// Fields are read as point_fields.hpp says; absolute per-point times are
// taken relative to the scan's timestamp when that is a real time (from the
// file names, or a times.txt of times since the epoch). info().point_fields
// are the first scan's (read when the folder is opened), and so is the
// intensity range every scan's remission is divided by (its field's type or
// values, io/intensity_scale.hpp), unless SourceOptions gives it.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "saloam/io/frame_source.hpp"
#include "saloam/io/intensity_scale.hpp"
#include "saloam/io/point_fields.hpp"
#include "saloam/sources/source_options.hpp"

namespace saloam {

class PointCloudFolder final : public FrameSource {
 public:
  /// `format` is kPcd or kPly; `path` a folder or one file of that format.
  PointCloudFolder(std::filesystem::path path, ScanFormat format, const SourceOptions& options);

  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  LabelledCloud scan(std::size_t i) override;

  [[nodiscard]] const std::filesystem::path& scan_file(std::size_t i) const { return files_.at(i); }

 private:
  void read_times(const std::optional<std::vector<double>>& name_stamps);
  void read_calibration_and_reference(const SourceOptions& options);
  void find_labels(const SourceOptions& options);
  [[nodiscard]] DecodedCloud decode(std::size_t i) const;

  std::filesystem::path path_;
  std::filesystem::path folder_;
  ScanFormat format_;
  std::vector<std::filesystem::path> files_;
  std::vector<std::filesystem::path> label_files_;  ///< empty, or one per scan
  bool stamps_are_absolute_ = false;
  IntensityScale intensity_;
  SourceInfo info_;
};

}  // namespace saloam
