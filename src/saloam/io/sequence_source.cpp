#include "saloam/io/sequence_source.hpp"

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace saloam {
namespace {

std::optional<std::vector<Pose>> sensor_camera_poses(const SequenceReader& reader) {
  const auto file = reader.root() / "poses_sensor.txt";
  if (!std::filesystem::exists(file)) return std::nullopt;
  std::vector<Pose> poses = read_kitti_poses(file);
  if (poses.size() != reader.size()) {
    throw InputError(file, fmt::format("{} poses for {} scans", poses.size(), reader.size()));
  }
  return poses;
}

}  // namespace

SequenceFolderSource::SequenceFolderSource(SequenceReader reader, bool read_calib) : reader_(std::move(reader)) {
  info_.name = reader_.root().string();
  info_.times = reader_.times();
  info_.has_labels = reader_.has_labels();
  info_.rereadable = true;
  if (read_calib && reader_.has_calib()) info_.velo_to_cam = reader_.velo_to_cam();
  if (reader_.has_poses()) info_.camera_poses = reader_.camera_poses();
  info_.sensor_camera_poses = sensor_camera_poses(reader_);
  info_.folder = reader_.root();
}

}  // namespace saloam
