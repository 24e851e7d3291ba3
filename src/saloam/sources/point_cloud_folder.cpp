#include "saloam/sources/point_cloud_folder.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/pcd.hpp"
#include "saloam/io/ply.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/sources/scan_files.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

std::string_view extension_of(ScanFormat format) { return format == ScanFormat::kPly ? ".ply" : ".pcd"; }

}  // namespace

PointCloudFolder::PointCloudFolder(fs::path path, ScanFormat format, const SourceOptions& options)
    : path_(std::move(path)), format_(format) {
  std::error_code ec;
  std::optional<std::vector<double>> name_stamps;
  if (fs::is_regular_file(path_, ec)) {
    folder_ = path_.parent_path().empty() ? fs::path(".") : path_.parent_path();
    files_ = {path_};
  } else if (fs::is_directory(path_, ec)) {
    folder_ = path_;
    ScanFiles listed = list_scan_files(path_, extension_of(format_));
    files_ = std::move(listed.files);
    name_stamps = std::move(listed.stamps);
    info_.folder = folder_;
  } else {
    throw InputError(path_, "not found");
  }
  info_.name = path_.string();
  info_.format = std::string(format_name(format_));
  read_times(name_stamps);
  read_calibration_and_reference(options);
  find_labels(options);
  info_.has_labels = !label_files_.empty();
  const DecodedCloud first = decode(0);
  info_.point_fields = first.fields;
  intensity_ = choose_intensity_scale(options.intensity_scale, first.intensity_type, first.cloud.remission);
  info_.notes.push_back(intensity_.note());
}

void PointCloudFolder::read_calibration_and_reference(const SourceOptions& options) {
  std::error_code ec;
  const bool whole_folder = info_.folder.has_value();
  const bool has_calib = whole_folder && fs::is_regular_file(folder_ / "calib.txt", ec);
  if (has_calib && !options.ignore_calib) {
    info_.velo_to_cam = read_velo_to_cam(folder_ / "calib.txt");
    info_.notes.push_back("calibration: calib.txt (Tr, velodyne to camera 0): poses in KITTI's camera frame");
  } else {
    info_.notes.push_back(has_calib ? "calibration: calib.txt ignored (--no-calib): runs in the LiDAR frame"
                                    : "calibration: none: runs in the LiDAR frame");
  }
  if (whole_folder && fs::is_regular_file(folder_ / "poses.txt", ec)) {
    auto poses = read_kitti_poses(folder_ / "poses.txt");
    if (poses.size() < files_.size()) {
      throw InputError(folder_ / "poses.txt", fmt::format("{} poses for {} scans", poses.size(), files_.size()));
    }
    poses.resize(files_.size());
    info_.camera_poses = std::move(poses);
    info_.notes.push_back(info_.velo_to_cam ? "reference: poses.txt (camera frame)" : "reference: poses.txt (LiDAR frame)");
  } else {
    info_.notes.push_back("reference: none (no poses.txt)");
  }
}

void PointCloudFolder::read_times(const std::optional<std::vector<double>>& name_stamps) {
  std::error_code ec;
  const fs::path times_file = folder_ / "times.txt";
  if (fs::is_directory(path_, ec) && fs::is_regular_file(times_file, ec)) {
    info_.times = saloam::read_times(times_file);
    if (info_.times.size() < files_.size()) {
      throw InputError(times_file, fmt::format("{} timestamps for {} scans", info_.times.size(), files_.size()));
    }
    info_.times.resize(files_.size());
    info_.notes.push_back("times: times.txt");
  } else if (name_stamps) {
    info_.times = *name_stamps;
    info_.notes.push_back("times: from the file names");
  } else {
    info_.times.resize(files_.size());
    for (std::size_t i = 0; i < info_.times.size(); ++i) info_.times[i] = 0.1 * static_cast<double>(i);
    info_.notes.push_back("times: none found (no times.txt, names are not timestamps): 0.1 s steps assumed");
  }
  stamps_are_absolute_ = !info_.times.empty() && info_.times.front() > kAbsoluteTimeThreshold;
}

void PointCloudFolder::find_labels(const SourceOptions& options) {
  if (options.ignore_labels) return;
  std::error_code ec;
  const fs::path dir = options.labels.value_or(folder_ / "labels");
  if (!fs::is_directory(dir, ec)) {
    if (options.labels) throw InputError(dir, "labels folder not found");
    return;
  }
  std::vector<fs::path> found;
  for (const auto& file : files_) {
    fs::path label = dir / file.filename();
    label.replace_extension(".label");
    if (!fs::is_regular_file(label, ec)) {
      if (found.empty() && !options.labels) return;  // a labels/ folder of something else
      throw InputError(label, fmt::format("missing: labels for {} of {} scans", found.size(), files_.size()));
    }
    found.push_back(label);
  }
  label_files_ = std::move(found);
}

DecodedCloud PointCloudFolder::decode(std::size_t i) const {
  const fs::path& file = files_.at(i);
  const std::optional<double> stamp = stamps_are_absolute_ ? std::optional<double>(info_.times[i]) : std::nullopt;
  return format_ == ScanFormat::kPly ? read_ply_cloud(file, stamp) : read_pcd(file, stamp);
}

LabelledCloud PointCloudFolder::scan(std::size_t i) {
  const fs::path& file = files_.at(i);
  DecodedCloud decoded = decode(i);
  if (!label_files_.empty()) {
    const auto labels = read_label_file(label_files_[i]);
    if (labels.size() != decoded.points_in_file) {
      throw InputError(label_files_[i], fmt::format("{} labels for {} points in {}", labels.size(),
                                                    decoded.points_in_file, file.filename().string()));
    }
    if (decoded.cloud.size() != decoded.points_in_file) {
      throw InputError(file, fmt::format("{} of its points were dropped (non-finite or out-of-range coordinates or "
                                         "rings): its labels cannot be matched to the points kept",
                                         decoded.points_in_file - decoded.cloud.size()));
    }
    for (std::size_t k = 0; k < labels.size(); ++k) {
      decoded.cloud.label[k] = static_cast<std::uint16_t>(labels[k] & 0xFFFFu);
      decoded.cloud.instance[k] = static_cast<std::uint16_t>(labels[k] >> 16);
    }
    decoded.cloud.has_labels = true;
  } else {
    // A `label` field alone is not taken for SemanticKITTI class ids.
    std::fill(decoded.cloud.label.begin(), decoded.cloud.label.end(), 0);
    std::fill(decoded.cloud.instance.begin(), decoded.cloud.instance.end(), 0);
    decoded.cloud.has_labels = false;
  }
  intensity_.apply(decoded.cloud);
  return std::move(decoded.cloud);
}

}  // namespace saloam
