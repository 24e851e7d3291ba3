#pragma once
// Built-in driving routes for the simulator, as LiDAR trajectories
// Q_i = T_L0<-Li at 10 Hz (world = first LiDAR frame, z up; "ramp-start":
// the first frame's position and heading, z up), with realistic
// speeds (about 8-12 m/s on straights, slower in curves) and smooth curvature.

#include <functional>
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
///  - "hill-climb": 2.7 km of mountain road, no revisit: grades of 8-15 %,
///    about 170 m of height range, two crests and a sag, three hairpins,
///    cross-slopes of 2.5-6 % (issue #43).
///  - "ramp-start": a garage ramp of 20 deg for 30 m, levelling out over
///    40 m, then 1.3 km through town on level ground: the first frame is
///    tilted 20 deg against gravity (its world keeps z up, not the first
///    frame's orientation).
///  - "handheld-walk": 60 s on foot (about 68 m along a street with two
///    corners and two stops), the LiDAR held at head height and pitched a
///    little down, the gait's sway and the hand's shake, ten look-arounds at
///    up to ~190 deg/s (sim/handheld_walk.hpp); world z up.
std::vector<std::string> preset_names();

/// Whether the preset's road lies on a hillside whose ground the simulated
/// world shapes from the poses (WorldOptions::hillside): true for
/// "hill-climb". The other presets' roll comes from rolling hills that their
/// worlds, built before, do not follow across the road.
bool preset_on_hillside(const std::string& name);

/// LiDAR poses of a preset at the given frame period. Throws ConfigError for
/// an unknown name (the message lists the valid ones).
std::vector<Pose> preset_trajectory(const std::string& name, double frame_period = 0.1);

/// A preset's LiDAR pose at time t [s] from its start, in the frame of
/// preset_trajectory's poses: for presets whose motion is not linear between
/// frames (the handheld walk), which the simulator samples within every
/// sweep. Empty for the driving presets.
using ContinuousMotion = std::function<Pose(double)>;
ContinuousMotion preset_motion(const std::string& name);

/// The track a preset's world is built along, one pose per frame: the
/// trajectory itself, except for the handheld walk (its path at the sensor's
/// height, level, without the gait or the look-arounds).
std::vector<Pose> preset_track(const std::string& name, double frame_period = 0.1);

/// KITTI's velodyne-to-camera extrinsic of sequences 00-02 (used for presets).
Pose kitti_velo_to_cam();

}  // namespace saloam
