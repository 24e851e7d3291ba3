#include "saloam/io/sequence.hpp"

#include <algorithm>
#include <map>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace fs = std::filesystem;

namespace saloam {

std::string frame_name(std::size_t index) { return fmt::format("{:06d}", index); }

namespace {

/// The number of a scan file name ("000042.bin" -> 42), or nullopt when the
/// stem is not all digits.
std::optional<std::size_t> scan_number(const fs::path& file) {
  const std::string stem = file.stem().string();
  const auto is_digit = [](char c) { return c >= '0' && c <= '9'; };
  if (stem.empty() || stem.size() > 9 || !std::all_of(stem.begin(), stem.end(), is_digit)) return std::nullopt;
  return static_cast<std::size_t>(std::stoul(stem));
}

/// The .bin scans of `velodyne`, indexed by their number: entry i is scan i.
/// Throws InputError for an entry named like a scan that is not a file, a
/// name that is not a number, two files of one number, or a gap (which would
/// pair every later scan with the wrong pose and timestamp).
std::vector<fs::path> numbered_scans(const fs::path& velodyne) {
  std::map<std::size_t, fs::path> by_number;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(velodyne, ec)) {
    if (entry.path().extension() != ".bin") continue;
    if (!entry.is_regular_file(ec)) {
      throw InputError(entry.path(), entry.is_directory(ec) ? "is a directory, not a scan file"
                                                            : "is not a regular file (expected a scan file)");
    }
    const auto number = scan_number(entry.path());
    if (!number) throw InputError(entry.path(), "scan names must be frame numbers (NNNNNN.bin)");
    const auto [it, inserted] = by_number.emplace(*number, entry.path());
    if (!inserted) {
      throw InputError(entry.path(), fmt::format("same frame number as {}", it->second.filename().string()));
    }
  }
  if (ec) throw InputError(velodyne, fmt::format("cannot list folder: {}", ec.message()));
  if (by_number.empty()) throw InputError(velodyne, "no .bin scans");
  std::vector<fs::path> scans;
  for (const auto& [number, file] : by_number) {
    if (number != scans.size()) {
      throw InputError(velodyne / (frame_name(scans.size()) + ".bin"),
                       fmt::format("missing scan: the scans must be numbered without gaps from {} (found {} next), "
                                   "or every later scan would get the wrong pose and timestamp",
                                   frame_name(0) + ".bin", file.filename().string()));
    }
    scans.push_back(file);
  }
  return scans;
}

/// The labels folder: `given` (which must exist), else `root`/labels (which may not).
fs::path labels_folder(const fs::path& root, const std::optional<fs::path>& given) {
  if (!given) return root / "labels";
  std::error_code ec;
  if (!fs::is_directory(*given, ec)) throw InputError(*given, "labels folder not found");
  return *given;
}

/// Per scan, its .label file in `labels_dir` (same stem); empty when the
/// folder holds none of them. Throws InputError when only some scans have
/// one, or when the folder was `asked_for` and holds none.
std::vector<std::optional<fs::path>> matching_labels(const std::vector<fs::path>& scans, const fs::path& labels_dir,
                                                     bool asked_for) {
  std::vector<std::optional<fs::path>> labels;
  std::size_t found = 0;
  std::error_code ec;
  for (const auto& scan : scans) {
    fs::path label = labels_dir / scan.filename();
    label.replace_extension(".label");
    if (fs::is_regular_file(label, ec)) {
      labels.emplace_back(label);
      ++found;
    } else {
      labels.emplace_back(std::nullopt);
    }
  }
  if (found > 0 && found != scans.size()) {
    const auto missing = std::find(labels.begin(), labels.end(), std::nullopt) - labels.begin();
    throw InputError(labels_dir, fmt::format("labels for {} of {} scans; first missing: {}", found, scans.size(),
                                             scans[static_cast<std::size_t>(missing)].stem().string() + ".label"));
  }
  if (found == 0 && asked_for) throw InputError(labels_dir, "no .label files matching the scans");
  if (found == 0) labels.clear();
  return labels;
}

/// The first `count` entries of what `file` holds (a sequence may hold only
/// its first scans); throws InputError when it holds fewer.
template <typename T>
std::vector<T> first_entries(std::vector<T> entries, std::size_t count, const fs::path& file, const char* what) {
  if (entries.size() < count) throw InputError(file, fmt::format("{} {} for {} scans", entries.size(), what, count));
  entries.resize(count);
  return entries;
}

/// Scan times without a times.txt: 10 Hz from 0 s.
std::vector<double> nominal_times(std::size_t count) {
  std::vector<double> times(count);
  for (std::size_t i = 0; i < count; ++i) times[i] = 0.1 * static_cast<double>(i);
  return times;
}

}  // namespace

SequenceReader::SequenceReader(fs::path root, SequenceOptions options)
    : root_(std::move(root)), options_(std::move(options)) {
  std::error_code ec;
  if (!fs::is_directory(root_, ec)) {
    throw InputError(root_, fs::exists(root_, ec) ? "is not a folder (expected a sequence folder)"
                                                  : "sequence folder not found");
  }
  const fs::path velodyne = root_ / "velodyne";
  if (!fs::is_directory(velodyne, ec)) throw InputError(velodyne, "missing velodyne/ folder of .bin scans");
  scan_files_ = numbered_scans(velodyne);

  const fs::path labels_dir = labels_folder(root_, options_.labels_dir);
  if (!options_.ignore_labels && fs::is_directory(labels_dir, ec)) {
    label_files_ = matching_labels(scan_files_, labels_dir, options_.labels_dir.has_value());
  }
  labels_available_ = !label_files_.empty();
  if (!labels_available_) label_files_.assign(scan_files_.size(), std::nullopt);

  // Absent is allowed; anything in their place (a folder, a link to a
  // device, a FIFO) is read and refused by the reader, never taken for absent.
  const fs::path times_file = root_ / "times.txt";
  has_times_file_ = path_taken(times_file);
  times_ = has_times_file_ ? first_entries(read_times(times_file), scan_files_.size(), times_file, "timestamps")
                           : nominal_times(scan_files_.size());
  const fs::path poses_file = root_ / "poses.txt";
  if (path_taken(poses_file)) {
    camera_poses_ = first_entries(read_kitti_poses(poses_file), scan_files_.size(), poses_file, "poses");
  }
}

LabelledCloud SequenceReader::load_scan(std::size_t index, ScanReadStats* stats) const {
  if (index >= scan_files_.size()) {
    throw InputError(root_, fmt::format("scan index {} out of range (sequence has {})", index, scan_files_.size()));
  }
  return read_scan(scan_files_[index], label_files_[index], stats);
}

bool SequenceReader::has_calib() const { return path_taken(root_ / "calib.txt"); }

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
  create_folder(root_ / "velodyne");
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
