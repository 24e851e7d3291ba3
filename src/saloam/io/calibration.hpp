#pragma once
// KITTI calibration and the conversion between camera-frame and LiDAR-frame
// poses. Convention (../shared/data/kitti/README.md):
//   P_i = T_C0_0<-C0_i  (poses.txt),   Tr = T_C0<-L  (calib.txt, p_cam = Tr p_velo)
//   Q_i = T_L0<-Li = Tr^-1 * P_i * Tr  and back  P_i = Tr * Q_i * Tr^-1.

#include <filesystem>
#include <istream>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

/// Reads the `Tr:` line of a KITTI calib.txt. Also accepts a file holding only
/// 12 numbers on one line (several such lines are a pose file: an
/// InputError), or lines "NN: 12 numbers" (the per-sequence list in
/// ../shared/data/kitti/calib_velo_to_cam.txt; pass `sequence` to pick one).
Pose read_velo_to_cam(const std::filesystem::path& file, int sequence = -1);
/// The same over an open stream; `file` names it in errors.
Pose read_velo_to_cam(std::istream& in, const std::filesystem::path& file, int sequence = -1);
/// Writes a calib.txt with P0..P3 (KITTI's rectified projections) and `Tr:`.
void write_calib(const std::filesystem::path& file, const Pose& velo_to_cam);

/// Camera-frame poses P_i (world = first camera frame) to LiDAR-frame poses
/// Q_i = Tr^-1 P_i Tr (world = first LiDAR frame).
std::vector<Pose> camera_to_lidar_poses(const std::vector<Pose>& camera_poses, const Pose& velo_to_cam);
/// Inverse of camera_to_lidar_poses: P_i = Tr Q_i Tr^-1.
std::vector<Pose> lidar_to_camera_poses(const std::vector<Pose>& lidar_poses, const Pose& velo_to_cam);

}  // namespace saloam
