#pragma once
// The output folder of a run over a sequence: created on demand, and never
// the sequence folder itself, whose poses.txt (the ground truth) a run's
// poses.txt would overwrite.

#include <filesystem>
#include <optional>

#include "saloam/core/types.hpp"
#include "saloam/io/frame_source.hpp"

namespace saloam {

/// Creates `out_dir` (and its parents); InputError when it is the run's
/// sequence folder `sequence` (when the frames come from one), naming both
/// and what would be lost.
void prepare_output_folder(const std::filesystem::path& out_dir, const std::optional<std::filesystem::path>& sequence);

/// The velodyne-to-camera Tr for a run's KITTI pose files: the source's, so
/// that poses.txt compares with the ground truth. A source without one (a
/// folder opened with --no-calib) gives none: the pose files then hold
/// LiDAR-frame poses, which the log says.
std::optional<Pose> output_velo_to_cam(const SourceInfo& source);

}  // namespace saloam
