#pragma once
// A KITTI raw drive folder (e.g. 2011_09_26/2011_09_26_drive_0005_sync) as a
// FrameSource (file formats in io/kitti_raw.hpp):
//   DRIVE/velodyne_points/data/NNNNNNNNNN.bin   the scans, numbered without gaps
//   DRIVE/velodyne_points/timestamps.txt        scan times (laser facing forward);
//                                               _start/_end: the sweeps' bounds
//   DRIVE/oxts/data/NNNNNNNNNN.txt               GPS/INS, one record per scan
//   DRIVE/calib_imu_to_velo.txt, or the date folder's (DRIVE/..)
// Times are seconds since the first scan. The reference poses are the oxts
// records through KITTI's convertOxtsToPose (IMU poses, Mercator scale from
// the first latitude) expressed in the LiDAR frame with calib_imu_to_velo
// (Q_i = T_velo<-imu P_i T_velo<-imu^-1); without that file they stay IMU
// poses (said in info().notes). oxts records are paired with scans by index,
// as in the synchronised (_sync) drives; a drive with another number of oxts
// records than scans (an unsynchronised _extract drive), or a gap in their
// numbers, has no reference (the notes say why).
// No Tr: a KITTI raw drive runs in the LiDAR frame, and info().camera_poses
// holds the reference in the LiDAR frame (Q_i). Labels only from
// SourceOptions::labels (a drive has no labels folder of its own).
// Remission is divided by the range found in the first scan's values, or
// given (io/intensity_scale.hpp).

#include <filesystem>
#include <optional>
#include <vector>

#include "saloam/io/frame_source.hpp"
#include "saloam/io/intensity_scale.hpp"
#include "saloam/sources/source_options.hpp"

namespace saloam {

class KittiRawDrive final : public FrameSource {
 public:
  KittiRawDrive(std::filesystem::path drive, const SourceOptions& options);

  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  LabelledCloud scan(std::size_t i) override;

  /// Seconds since the epoch (the recording PC's clock) of the first scan.
  [[nodiscard]] double first_stamp() const { return first_stamp_; }
  /// Each sweep's duration [s] from timestamps_start/_end.txt, when present.
  [[nodiscard]] const std::optional<std::vector<double>>& sweep_durations() const { return sweep_durations_; }

 private:
  void read_times();
  void read_reference();

  std::filesystem::path drive_;
  std::vector<std::filesystem::path> scans_;
  std::vector<std::filesystem::path> label_files_;
  double first_stamp_ = 0.0;
  std::optional<std::vector<double>> sweep_durations_;
  IntensityScale intensity_;
  SourceInfo info_;
};

/// The folder holding calib_imu_to_velo.txt for `drive`: the drive itself or
/// its date folder; nullopt when neither has one.
std::optional<std::filesystem::path> find_imu_to_velo(const std::filesystem::path& drive);

}  // namespace saloam
