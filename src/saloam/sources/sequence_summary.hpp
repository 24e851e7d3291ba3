#pragma once
// What a scan source holds, for `saloam info`: frames, rate, duration, point
// fields, beams, calibration and reference. Reads a few scans, not all.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/io/frame_source.hpp"

namespace saloam {

enum class BeamMethod {
  kRingField,      ///< distinct values of the ring field
  kAzimuthWraps,   ///< points stored laser after laser: one azimuth revolution per laser
  kElevation,      ///< clusters of elevation angles
};

struct BeamEstimate {
  std::size_t beams = 0;
  BeamMethod method = BeamMethod::kElevation;
};

/// The beams of a scan: the distinct values of its ring field when it has
/// one. Else, when the points are stored laser after laser, each laser's
/// sweep in azimuth order (KITTI .bin files, many drivers' clouds: more
/// than 90 % of the steps between neighbouring points turn the same way,
/// and runs average 100 points or more), the revolutions of the unwrapped
/// azimuth from the first point to the last. Else the clusters of the
/// elevation angles of the points beyond 2 m (sorted, a gap above 0.15 deg
/// starts a new beam, a beam needs 0.1 % of the points): right for sensors
/// with exact, evenly spread lasers (the simulator, VLP-16), an undercount
/// for real HDL-64E scans, whose lasers' elevations blur into each other.
BeamEstimate estimate_beams(const LabelledCloud& cloud);

struct SequenceSummary {
  std::string format;            ///< "pcd"
  std::size_t frames = 0;
  double first_time = 0.0, last_time = 0.0;  ///< [s]
  double median_interval = 0.0;               ///< [s], 0 with one frame
  std::string fields;                         ///< of the scans read
  std::size_t scans_read = 0;
  double mean_points = 0.0;                   ///< per scan read
  std::optional<BeamEstimate> beams;          ///< of the first scan
  bool per_point_times = false;
  double sweep_seconds = 0.0;                 ///< span of the per-point times of the first scan
  bool labels = false;
  bool calibration = false;
  std::optional<std::size_t> reference_poses;
  std::vector<std::string> notes;             ///< SourceInfo::notes
};

/// Summarises `seq`, reading up to `scans_to_read` scans spread over it.
SequenceSummary summarize(FrameSource& source, std::size_t scans_to_read = 3);

}  // namespace saloam
