#pragma once
// What a run tells whoever follows it (the demo's second odometry, the live
// viewer of `--serve`) about each frame as soon as the frame is done. Called
// on the run's thread, between frames: a follower that takes long slows the
// run down.

#include <cstddef>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

struct FinishedFrame {
  std::size_t index = 0;  ///< processed-frame index (0 = the run's first frame)
  double time = 0;        ///< [s] the frame's timestamp
  const LabelledCloud& scan;
  /// The frame's best pose now, T_world<-LiDAR with world = the first frame:
  /// loop closed for `slam`, the odometry's for `odom`.
  Pose pose = Pose::Identity();
  /// Set when loop closure has just moved earlier frames: every frame's pose
  /// so far, this one's last (`pose` equals its last element).
  const std::vector<Pose>* corrected = nullptr;
  /// Loops accepted at this frame: (query, match) processed-frame indices.
  std::span<const std::pair<std::size_t, std::size_t>> loops;
};

using FrameFollower = std::function<void(const FinishedFrame&)>;

}  // namespace saloam
