#pragma once
// Scans made by formula for the tests that need a known sensor geometry.

#include "saloam/core/types.hpp"

namespace saloam::testing {

/// Points per laser of shuffled_vlp16_sphere(): one every 0.5 deg.
inline constexpr int kVlp16PointsPerLaser = 720;

/// A 16-laser scan (VLP-16: +15 to -15 deg in 2 deg steps) of a 10 m
/// sphere, 720 points per laser at 0.5 deg (half a step off the seam behind
/// the sensor), turning clockwise from behind the sensor (the sweep model's
/// default), with each point's laser in `ring` numbered from the BOTTOM (as
/// the Velodyne driver does) and its time in the sweep [0, 0.1) s in `time`;
/// stored in a shuffled order, so that the storage order says nothing of
/// the rings.
LabelledCloud shuffled_vlp16_sphere();

}  // namespace saloam::testing
