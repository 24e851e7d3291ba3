#pragma once
// The lasers of one scan, told apart as well as the scan allows: what
// `saloam info` reports as beams and what `--sensor auto` matches against
// the sensor profiles. In order of preference:
//   ring field     one laser per distinct value of LabelledCloud::ring (exact)
//   storage order  points stored laser after laser, each laser's sweep in
//                  azimuth order (KITTI .bin files, the simulator, organised
//                  driver clouds): more than 90 % of the steps between
//                  neighbouring points turn the same way and runs average 100
//                  points or more; a laser is one revolution of the unwrapped
//                  azimuth from the first point (exact while no laser misses
//                  half a turn)
//   elevation      clusters of the elevation angles of the points beyond 2 m
//                  (sorted, a gap above 0.15 deg starts a new laser, a laser
//                  needs 0.1 % of the points): right for sensors with evenly
//                  spread lasers (the simulator, VLP-16), an undercount for real
//                  HDL-64E scans, whose lasers' elevations blur into each other
// Elevations [deg] are atan2(z, hypot(x, y)) in the LiDAR frame; a laser's is
// the median of its points beyond 2 m (all of its points when none is).
// When the lasers are told apart exactly, elevations are taken about the
// axis they spin about, found from the lasers' cones: a scan handed over in
// a turned frame (a robot's base link) shows the sensor's own lasers.

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/types.hpp"

namespace saloam {

enum class BeamMethod {
  kRingField,      ///< distinct values of the ring field
  kAzimuthWraps,   ///< points stored laser after laser: one azimuth revolution per laser
  kElevation,      ///< clusters of elevation angles
};

struct FoundLasers {
  BeamMethod method = BeamMethod::kElevation;
  std::vector<double> elevation_deg;  ///< one per laser, top first
  /// The lasers' spin axis in the cloud's frame: its z unless the lasers,
  /// told apart exactly, spin about an axis more than 1 deg away.
  Eigen::Vector3d spin_axis = Eigen::Vector3d::UnitZ();
  [[nodiscard]] std::size_t count() const { return elevation_deg.size(); }
  /// Whether the lasers were told apart exactly (ring field or storage order).
  [[nodiscard]] bool exact() const { return method != BeamMethod::kElevation; }
};

FoundLasers find_lasers(const LabelledCloud& cloud);

/// "ring field", "points stored laser by laser", "elevation angles; no ring field"
const char* beam_method_text(BeamMethod method);

}  // namespace saloam
