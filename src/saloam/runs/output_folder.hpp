#pragma once
// The output folder of a run over a sequence: created on demand, and never
// the sequence folder itself, whose poses.txt (the ground truth) a run's
// poses.txt would overwrite.

#include <filesystem>
#include <optional>

#include "saloam/core/types.hpp"
#include "saloam/runs/frame_source.hpp"

namespace saloam {

/// Creates `out_dir` (and its parents); InputError when it is the run's
/// sequence folder `sequence` (when the frames come from one), naming both
/// and what would be lost.
void prepare_output_folder(const std::filesystem::path& out_dir, const std::optional<std::filesystem::path>& sequence);

/// The velodyne-to-camera Tr for a run's KITTI pose file: the source's
/// (calib.txt), so that poses.txt compares with the ground truth. InputError
/// when it has none, unless `lidar_frame` (--no-calib): then no Tr (calib.txt
/// is ignored) and the KITTI file holds LiDAR-frame poses.
std::optional<Pose> output_velo_to_cam(const FrameSource& source, bool lidar_frame);

}  // namespace saloam
