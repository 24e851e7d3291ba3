#include "saloam/sources/kitti_raw_drive.hpp"

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/io/kitti_raw.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/sources/scan_files.hpp"

namespace fs = std::filesystem;

namespace saloam {

std::optional<fs::path> find_imu_to_velo(const fs::path& drive) {
  std::error_code ec;
  for (const fs::path& folder : {drive, drive.parent_path()}) {
    if (fs::is_regular_file(folder / "calib_imu_to_velo.txt", ec)) return folder / "calib_imu_to_velo.txt";
  }
  return std::nullopt;
}

KittiRawDrive::KittiRawDrive(fs::path drive, const SourceOptions& options) : drive_(std::move(drive)) {
  std::error_code ec;
  if (!fs::is_directory(drive_, ec)) throw InputError(drive_, fs::exists(drive_, ec) ? "is not a folder (expected a KITTI raw drive)" : "not found");
  const fs::path data = drive_ / "velodyne_points" / "data";
  if (!fs::is_directory(data, ec)) throw InputError(data, "missing: a KITTI raw drive keeps its scans in velodyne_points/data/");
  scans_ = list_scan_files(data, ".bin").files;
  info_.name = drive_.string();
  info_.folder = drive_;
  info_.format = "kitti-raw";
  info_.point_fields = "x y z remission";
  read_times();
  info_.notes.push_back("calibration: none (a KITTI raw drive): runs in the LiDAR frame");
  read_reference();
  if (!options.ignore_labels && options.labels) {
    for (const auto& scan : scans_) {
      fs::path label = *options.labels / scan.filename();
      label.replace_extension(".label");
      if (!fs::is_regular_file(label, ec)) throw InputError(label, "missing label file for a scan");
      label_files_.push_back(label);
    }
  }
  info_.has_labels = !label_files_.empty();
  intensity_ = unread_intensity_scale(options.intensity_scale);
  if (!options.intensity_scale && !scans_.empty()) {
    try {
      intensity_ = choose_intensity_scale(std::nullopt, ScalarType::kFloat32, read_scan(scans_.front()).remission);
    } catch (const InputError&) {
      // The run fails on that scan, naming it; the range stays 1.
    }
  }
  info_.notes.push_back(intensity_.note());
}

void KittiRawDrive::read_times() {
  std::error_code ec;
  const fs::path file = drive_ / "velodyne_points" / "timestamps.txt";
  if (!fs::is_regular_file(file, ec)) {
    info_.times.resize(scans_.size());
    for (std::size_t i = 0; i < info_.times.size(); ++i) info_.times[i] = 0.1 * static_cast<double>(i);
    info_.notes.push_back("times: no velodyne_points/timestamps.txt, 0.1 s steps assumed");
    return;
  }
  std::vector<std::int64_t> stamps = read_kitti_timestamps_ns(file);
  if (stamps.size() < scans_.size()) throw InputError(file, fmt::format("{} timestamps for {} scans", stamps.size(), scans_.size()));
  stamps.resize(scans_.size());
  first_stamp_ = nanos_to_seconds(stamps.front());
  info_.times.resize(stamps.size());
  for (std::size_t i = 0; i < stamps.size(); ++i) info_.times[i] = nanos_to_seconds(stamps[i] - stamps.front());
  info_.notes.push_back("times: velodyne_points/timestamps.txt (laser facing forward), since the first scan");

  const fs::path start = drive_ / "velodyne_points" / "timestamps_start.txt";
  const fs::path end = drive_ / "velodyne_points" / "timestamps_end.txt";
  if (fs::is_regular_file(start, ec) && fs::is_regular_file(end, ec)) {
    const auto a = read_kitti_timestamps_ns(start);
    const auto b = read_kitti_timestamps_ns(end);
    if (a.size() >= scans_.size() && b.size() >= scans_.size()) {
      std::vector<double> durations(scans_.size());
      double sum = 0.0;
      for (std::size_t i = 0; i < durations.size(); ++i) sum += durations[i] = nanos_to_seconds(b[i] - a[i]);
      info_.notes.push_back(fmt::format("sweeps: {:.4f} s on average (timestamps_start/_end.txt)",
                                         sum / static_cast<double>(durations.size())));
      sweep_durations_ = std::move(durations);
    }
  }
}

void KittiRawDrive::read_reference() {
  std::error_code ec;
  const fs::path data = drive_ / "oxts" / "data";
  if (!fs::is_directory(data, ec) || !has_files_with_extension(data, ".txt")) {
    info_.notes.push_back("reference: none (no oxts/data/)");
    return;
  }
  std::vector<fs::path> files;
  try {
    files = list_scan_files(data, ".txt").files;
  } catch (const InputError& e) {
    info_.notes.push_back(fmt::format("reference: none: {}", e.what()));
    return;
  }
  if (files.size() != scans_.size()) {
    info_.notes.push_back(fmt::format("reference: none: {} oxts records for {} scans (an unsynchronised drive?)",
                                       files.size(), scans_.size()));
    return;
  }
  std::vector<OxtsRecord> records;
  records.reserve(files.size());
  for (const auto& f : files) records.push_back(read_oxts(f));
  std::vector<Pose> poses = oxts_to_poses(records);
  const auto calib = find_imu_to_velo(drive_);
  if (!calib) {
    info_.camera_poses = std::move(poses);
    info_.notes.push_back("reference: oxts/ (GPS/INS), IMU frame: no calib_imu_to_velo.txt");
    return;
  }
  const Pose velo_imu = read_imu_to_velo(*calib);
  const Pose imu_velo = velo_imu.inverse();
  for (auto& P : poses) P = orthonormalized(velo_imu * P * imu_velo);
  info_.camera_poses = std::move(poses);
  info_.notes.push_back(fmt::format("reference: oxts/ (GPS/INS) in the LiDAR frame via {}", calib->string()));
}

LabelledCloud KittiRawDrive::scan(std::size_t i) {
  LabelledCloud cloud =
      read_scan(scans_.at(i), label_files_.empty() ? std::nullopt : std::optional<fs::path>(label_files_[i]));
  intensity_.apply(cloud);
  return cloud;
}

}  // namespace saloam
