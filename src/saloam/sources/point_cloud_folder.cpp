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

PointCloudFolder::PointCloudFolder(fs::path path, ScanFormat format, const ScanSequenceOptions& options)
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
  } else {
    throw InputError(path_, "not found");
  }
  read_times(name_stamps);
  const bool whole_folder = files_.size() > 1 || fs::is_directory(path_, ec);
  if (whole_folder && fs::is_regular_file(folder_ / "calib.txt", ec)) {
    velo_to_cam_ = read_velo_to_cam(folder_ / "calib.txt");
    facts_.notes.push_back("calibration: calib.txt (Tr, velodyne to camera 0)");
  } else {
    facts_.notes.push_back("calibration: none: runs in the LiDAR frame");
  }
  if (whole_folder && fs::is_regular_file(folder_ / "poses.txt", ec)) {
    auto poses = read_kitti_poses(folder_ / "poses.txt");
    if (poses.size() < files_.size()) {
      throw InputError(folder_ / "poses.txt", fmt::format("{} poses for {} scans", poses.size(), files_.size()));
    }
    poses.resize(files_.size());
    poses_ = std::move(poses);
    facts_.notes.push_back(velo_to_cam_ ? "reference: poses.txt (camera frame)" : "reference: poses.txt (LiDAR frame)");
  } else {
    facts_.notes.push_back("reference: none (no poses.txt)");
  }
  find_labels(options);
}

void PointCloudFolder::read_times(const std::optional<std::vector<double>>& name_stamps) {
  std::error_code ec;
  const fs::path times_file = folder_ / "times.txt";
  if (fs::is_directory(path_, ec) && fs::is_regular_file(times_file, ec)) {
    times_ = saloam::read_times(times_file);
    if (times_.size() < files_.size()) {
      throw InputError(times_file, fmt::format("{} timestamps for {} scans", times_.size(), files_.size()));
    }
    times_.resize(files_.size());
    facts_.notes.push_back("times: times.txt");
  } else if (name_stamps) {
    times_ = *name_stamps;
    facts_.notes.push_back("times: from the file names");
  } else {
    times_.resize(files_.size());
    for (std::size_t i = 0; i < times_.size(); ++i) times_[i] = 0.1 * static_cast<double>(i);
    facts_.notes.push_back("times: none found (no times.txt, names are not timestamps): 0.1 s steps assumed");
  }
  stamps_are_absolute_ = !times_.empty() && times_.front() > kAbsoluteTimeThreshold;
}

void PointCloudFolder::find_labels(const ScanSequenceOptions& options) {
  if (options.ignore_labels) return;
  std::error_code ec;
  const fs::path dir = options.labels_dir.value_or(folder_ / "labels");
  if (!fs::is_directory(dir, ec)) {
    if (options.labels_dir) throw InputError(dir, "labels folder not found");
    return;
  }
  std::vector<fs::path> found;
  for (const auto& file : files_) {
    fs::path label = dir / file.filename();
    label.replace_extension(".label");
    if (!fs::is_regular_file(label, ec)) {
      if (found.empty() && !options.labels_dir) return;  // a labels/ folder of something else
      throw InputError(label, fmt::format("missing: labels for {} of {} scans", found.size(), files_.size()));
    }
    found.push_back(label);
  }
  label_files_ = std::move(found);
}

LabelledCloud PointCloudFolder::scan(std::size_t i) {
  const fs::path& file = files_.at(i);
  const std::optional<double> stamp = stamps_are_absolute_ ? std::optional<double>(times_[i]) : std::nullopt;
  DecodedCloud decoded = format_ == ScanFormat::kPly ? read_ply_cloud(file, stamp) : read_pcd(file, stamp);
  fields_ = decoded.fields;
  if (!label_files_.empty()) {
    const auto labels = read_label_file(label_files_[i]);
    if (labels.size() != decoded.points_in_file) {
      throw InputError(label_files_[i], fmt::format("{} labels for {} points in {}", labels.size(),
                                                    decoded.points_in_file, file.filename().string()));
    }
    if (decoded.cloud.size() != decoded.points_in_file) {
      throw InputError(file, "has points with NaN coordinates: its labels cannot be matched to the points kept");
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
  return std::move(decoded.cloud);
}

}  // namespace saloam
