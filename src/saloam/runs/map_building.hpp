#pragma once
// Builds the global semantic map of a sequence from its scans and a
// trajectory (odometry or SLAM output, or ground truth).

#include <cstddef>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/mapping/semantic_map.hpp"

namespace saloam {

/// Inserts scan `first_frame + k` with lidar_poses[k] (every `frame_step`-th
/// pose) into a SemanticMap and returns its points (world frame).
LabelledCloud build_semantic_map(const SequenceReader& reader, const std::vector<Pose>& lidar_poses,
                                 std::size_t first_frame, const SemanticMapOptions& options,
                                 std::size_t frame_step = 1, bool show_progress = true);

}  // namespace saloam
