#pragma once
// Trajectory files: KITTI (12 numbers per line, row-major 3x4 [R|t]) and TUM
// (timestamp x y z qx qy qz qw). Bad lines are errors with their line number.

#include <filesystem>
#include <istream>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

// Every reader skips a UTF-8 byte-order mark at the start of the file. A
// rotation must be orthonormal within kRotationTolerance (lie.hpp) with
// det > 0; it is re-orthonormalized on load. TUM timestamps must increase.
// Each reader also takes an open stream, `file` naming it in errors (the
// path versions open the file and call those); every problem is an
// InputError naming the file and the line.

/// Reads a KITTI pose file. Rotations are re-orthonormalized on load.
std::vector<Pose> read_kitti_poses(const std::filesystem::path& file);
std::vector<Pose> read_kitti_poses(std::istream& in, const std::filesystem::path& file);
void write_kitti_poses(const std::filesystem::path& file, const std::vector<Pose>& poses);
/// One KITTI line (no newline) for streaming writers.
std::string kitti_pose_line(const Pose& pose);

/// Reads a TUM trajectory (lines starting with '#' are comments).
Trajectory read_tum_trajectory(const std::filesystem::path& file);
Trajectory read_tum_trajectory(std::istream& in, const std::filesystem::path& file);
void write_tum_trajectory(const std::filesystem::path& file, const Trajectory& trajectory);
/// One TUM line (no newline) for streaming writers.
std::string tum_pose_line(double timestamp, const Pose& pose);

enum class TrajectoryFormat { kKitti, kTum };

/// Reads a KITTI or TUM trajectory, deciding by the number of columns
/// (12 = KITTI, 8 = TUM; stored in `format` when given). KITTI timestamps are
/// the frame indices * 0.1 s.
Trajectory read_trajectory(const std::filesystem::path& file, TrajectoryFormat* format = nullptr);
Trajectory read_trajectory(std::istream& in, const std::filesystem::path& file, TrajectoryFormat* format = nullptr);

/// Reads a times.txt file (one timestamp in seconds per line, increasing).
std::vector<double> read_times(const std::filesystem::path& file);
std::vector<double> read_times(std::istream& in, const std::filesystem::path& file);
void write_times(const std::filesystem::path& file, const std::vector<double>& times);

}  // namespace saloam
