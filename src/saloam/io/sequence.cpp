#include "saloam/io/sequence.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace fs = std::filesystem;

namespace saloam {

std::string frame_name(std::size_t index) { return fmt::format("{:06d}", index); }

SequenceReader::SequenceReader(fs::path root, SequenceOptions options)
    : root_(std::move(root)), options_(std::move(options)) {
  std::error_code ec;
  if (!fs::is_directory(root_, ec)) throw InputError(root_, "sequence folder not found");
  const fs::path velodyne = root_ / "velodyne";
  if (!fs::is_directory(velodyne, ec)) throw InputError(velodyne, "missing velodyne/ folder of .bin scans");
  for (const auto& entry : fs::directory_iterator(velodyne)) {
    if (entry.is_regular_file() && entry.path().extension() == ".bin") scan_files_.push_back(entry.path());
  }
  std::sort(scan_files_.begin(), scan_files_.end());
  if (scan_files_.empty()) throw InputError(velodyne, "no .bin scans");

  // Labels: a predictions folder if given, else labels/ when it exists.
  fs::path labels_dir = root_ / "labels";
  if (options_.labels_dir) {
    labels_dir = *options_.labels_dir;
    if (!fs::is_directory(labels_dir, ec)) throw InputError(labels_dir, "labels folder not found");
  }
  if (!options_.ignore_labels && fs::is_directory(labels_dir, ec)) {
    std::size_t found = 0;
    for (const auto& scan : scan_files_) {
      fs::path label = labels_dir / scan.filename();
      label.replace_extension(".label");
      if (fs::is_regular_file(label, ec)) {
        label_files_.emplace_back(label);
        ++found;
      } else {
        label_files_.emplace_back(std::nullopt);
      }
    }
    if (found > 0 && found != scan_files_.size()) {
      const auto missing = std::find(label_files_.begin(), label_files_.end(), std::nullopt) - label_files_.begin();
      throw InputError(labels_dir, fmt::format("labels for {} of {} scans; first missing: {}", found,
                                               scan_files_.size(),
                                               scan_files_[static_cast<std::size_t>(missing)].stem().string() + ".label"));
    }
    if (found == 0 && options_.labels_dir) throw InputError(labels_dir, "no .label files matching the scans");
    labels_available_ = found > 0;
  }
  if (!labels_available_) label_files_.assign(scan_files_.size(), std::nullopt);

  const fs::path times_file = root_ / "times.txt";
  if (fs::is_regular_file(times_file, ec)) {
    times_ = read_times(times_file);
    if (times_.size() < scan_files_.size()) {
      throw InputError(times_file, fmt::format("{} timestamps for {} scans", times_.size(), scan_files_.size()));
    }
    times_.resize(scan_files_.size());
    has_times_file_ = true;
  } else {
    times_.resize(scan_files_.size());
    for (std::size_t i = 0; i < times_.size(); ++i) times_[i] = 0.1 * static_cast<double>(i);
  }

  const fs::path poses_file = root_ / "poses.txt";
  if (fs::is_regular_file(poses_file, ec)) {
    camera_poses_ = read_kitti_poses(poses_file);
    if (camera_poses_.size() < scan_files_.size()) {
      throw InputError(poses_file, fmt::format("{} poses for {} scans", camera_poses_.size(), scan_files_.size()));
    }
    camera_poses_.resize(scan_files_.size());
  }
}

LabelledCloud SequenceReader::load_scan(std::size_t index, ScanReadStats* stats) const {
  if (index >= scan_files_.size()) {
    throw InputError(root_, fmt::format("scan index {} out of range (sequence has {})", index, scan_files_.size()));
  }
  return read_scan(scan_files_[index], label_files_[index], stats);
}

bool SequenceReader::has_calib() const {
  std::error_code ec;
  return fs::is_regular_file(root_ / "calib.txt", ec);
}

Pose SequenceReader::velo_to_cam() const {
  const fs::path calib = root_ / "calib.txt";
  if (!has_calib()) throw InputError(calib, "missing calib.txt (needed for the velodyne-to-camera transform Tr)");
  return read_velo_to_cam(calib);
}

std::vector<Pose> SequenceReader::lidar_poses() const {
  if (!has_poses()) throw InputError(root_ / "poses.txt", "missing ground-truth poses");
  return camera_to_lidar_poses(camera_poses_, velo_to_cam());
}

SequenceWriter::SequenceWriter(fs::path root) : root_(std::move(root)) {
  fs::create_directories(root_ / "velodyne");
}

void SequenceWriter::write_scan(std::size_t index, const LabelledCloud& cloud) const {
  write_scan_bin(root_ / "velodyne" / (frame_name(index) + ".bin"), cloud);
  if (cloud.has_labels) write_scan_labels(root_ / "labels" / (frame_name(index) + ".label"), cloud);
}

void SequenceWriter::write_camera_poses(const std::vector<Pose>& camera_poses) const {
  write_kitti_poses(root_ / "poses.txt", camera_poses);
}

void SequenceWriter::write_calib(const Pose& velo_to_cam) const { saloam::write_calib(root_ / "calib.txt", velo_to_cam); }

void SequenceWriter::write_times(const std::vector<double>& times) const { saloam::write_times(root_ / "times.txt", times); }

}  // namespace saloam
