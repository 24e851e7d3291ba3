#pragma once
// Built-in driving routes for the simulator, as LiDAR trajectories
// Q_i = T_L0<-Li at 10 Hz (world = first LiDAR frame, z up), with realistic
// speeds (about 8-12 m/s on straights, slower in curves) and smooth curvature.

#include <string>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

/// Names of the built-in routes:
///  - "urban-loop": a ~1 km city loop (rounded blocks) that drives its first
///    ~200 m again at the end (same-direction revisit).
///  - "figure-eight": a figure eight with a crossing in the middle, a U-turn
///    and part of the route driven back in the opposite lane (reverse revisit).
///  - "straight": 400 m of gently curving road, no revisit (quick tests).
std::vector<std::string> preset_names();

/// LiDAR poses of a preset at the given frame period. Throws ConfigError for
/// an unknown name (the message lists the valid ones).
std::vector<Pose> preset_trajectory(const std::string& name, double frame_period = 0.1);

/// KITTI's velodyne-to-camera extrinsic of sequences 00-02 (used for presets).
Pose kitti_velo_to_cam();

}  // namespace saloam
