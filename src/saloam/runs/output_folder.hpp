#pragma once
// The output folder of a run over a sequence: created on demand, and never
// the sequence folder itself, whose poses.txt (the ground truth) a run's
// poses.txt would overwrite.

#include <filesystem>
#include <optional>

#include "saloam/io/sequence.hpp"

namespace saloam {

/// Creates `out_dir` (and its parents); InputError when it is the sequence
/// folder of `reader`, naming both and what would be lost.
void prepare_output_folder(const std::filesystem::path& out_dir, const SequenceReader& reader);

/// The velodyne-to-camera Tr for a run's KITTI pose file: calib.txt's, so
/// that poses.txt compares with the ground truth. InputError when calib.txt
/// is missing, unless `lidar_frame` (--no-calib): then no Tr (calib.txt is
/// ignored) and the KITTI file holds LiDAR-frame poses.
std::optional<Pose> output_velo_to_cam(const SequenceReader& reader, bool lidar_frame);

}  // namespace saloam
