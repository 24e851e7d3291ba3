#pragma once
// What a scan source holds, for `saloam info`: frames, rate, duration, point
// fields, beams, calibration and reference. Reads a few scans, not all.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/io/frame_source.hpp"
#include "saloam/sources/lasers.hpp"

namespace saloam {

struct SequenceSummary {
  std::string format;            ///< "pcd"
  std::size_t frames = 0;
  double first_time = 0.0, last_time = 0.0;  ///< [s]
  double median_interval = 0.0;               ///< [s], 0 with one frame
  std::string fields;                         ///< of the scans read
  std::size_t scans_read = 0;
  double mean_points = 0.0;                   ///< per scan read
  std::optional<FoundLasers> lasers;          ///< of the first scan (lasers.hpp)
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
