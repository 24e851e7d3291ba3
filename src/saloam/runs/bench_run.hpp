#pragma once
// The odometry's speed over a frame source (`saloam bench`): the time of
// each frame's registration (reading the scan is not timed), per stage, wall
// clock and the thread's CPU time, the work behind it, and peak memory.

#include <cstddef>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/io/frame_source.hpp"
#include "saloam/odometry/semantic_odometry.hpp"

namespace saloam {

struct BenchResult {
  std::size_t frames = 0;
  double points_per_scan = 0;
  bool semantics = false;             ///< semantics on and the source has labels
  std::vector<double> frame_wall_ms;  ///< per frame: SemanticOdometry::register_frame
  std::vector<double> frame_cpu_ms;   ///< the same, CPU time of the calling thread
  std::vector<FrameTimings> stage_wall_ms, stage_cpu_ms;  ///< per frame and stage
  /// The source's stages (e.g. segmentation, on threads of their own) per frame.
  std::vector<SourceStageTimes> source_stages;
  double run_wall_s = 0;              ///< the whole run, reading and source stages included
  // Work per frame (means), to explain the timings: features after
  // downsampling, local-map size and association rounds (neighbour queries
  // of every feature).
  double edge_features = 0, planar_features = 0;
  double map_edge_points = 0, map_planar_points = 0;
  double association_rounds = 0;
  double peak_rss_mib = 0;
  bool interrupted = false;
};

/// Runs SemanticOdometry over every frame of `source` and times it; writes nothing.
BenchResult run_bench(FrameSource& source, const OdometryConfig& config, bool show_progress = true);

}  // namespace saloam
