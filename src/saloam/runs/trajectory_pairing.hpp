#pragma once
// Two trajectory files made comparable, as `saloam eval --gt GT --est EST`
// compares them (and the Python module's saloam.eval): read (KITTI or TUM),
// in one frame (a TUM file, LiDAR frame, against a KITTI file, camera frame,
// needs calib.txt's Tr), then paired: two TUM files by time (the nearest
// within 0.02 s, or half the ground truth's median interval when that is
// less), anything else by frame (a run's result starts at the first frame
// its summary.json records, anything else at frame 0).

#include <filesystem>
#include <optional>

#include "saloam/io/trajectory_io.hpp"

namespace saloam {

struct TrajectoryPair {
  Trajectory gt, est;  ///< pose i of one belongs to pose i of the other
};

/// InputError naming the file when one cannot be read, the formats differ
/// without `calib_file`, or the poses cannot be paired. Warns (log) when GT
/// is a simulated poses.txt with poses_sensor.txt beside it, and about poses
/// left without a partner.
TrajectoryPair read_trajectory_pair(const std::filesystem::path& gt_file, const std::filesystem::path& est_file,
                                    const std::optional<std::filesystem::path>& calib_file);

}  // namespace saloam
