#pragma once
// Constant-velocity de-skewing: a spinning LiDAR measures each return at a
// different instant of the sweep while the vehicle moves. Each point is moved
// into the sensor frame at the instant the scan's pose refers to
// (`pose_time_in_sweep`), assuming the motion over the sweep is the
// constant-velocity motion of the last frame.

#include "saloam/core/lie.hpp"
#include "saloam/odometry/features.hpp"

namespace saloam {

/// `frame_motion` = twist log(T_prev^-1 T_curr) of one frame period `frame_period` [s].
/// A point measured at sweep time tau maps with exp((tau - pose_time) / period * twist).
void deskew(FeatureCloud& cloud, const Vector6d& frame_motion, double frame_period, double pose_time_in_sweep);
/// A copy of `scan` with its edges and planars de-skewed as above.
ScanFeatures deskewed(const ScanFeatures& scan, const Vector6d& frame_motion, double frame_period, double pose_time_in_sweep);

}  // namespace saloam
