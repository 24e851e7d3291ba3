#pragma once
// Builds the global semantic map of a run from its scans and a trajectory
// (odometry or SLAM output, or ground truth): from a source that can read
// its scans again, or from compact copies kept while a stream went by.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/mapping/semantic_map.hpp"
#include "saloam/io/frame_source.hpp"

namespace saloam {

/// Inserts scan k with lidar_poses[k] (every `frame_step`-th pose) into a
/// SemanticMap and returns its points (world frame). The source must be
/// rereadable.
LabelledCloud build_semantic_map(FrameSource& source, const std::vector<Pose>& lidar_poses,
                                 const SemanticMapOptions& options, std::size_t frame_step,
                                 bool show_progress = true);

/// The scans of a streamed run that go into its map, kept as it goes by:
/// every `frame_step`-th scan, voxel-downsampled in its sensor frame at the
/// map's resolution (what the map keeps of it anyway: one point per voxel,
/// dynamic classes and far returns left out), each point in 10 bytes
/// (centimetre coordinates, class, remission), so a run keeps a few hundred
/// kilobytes per scan instead of megabytes.
class MapScanStore {
 public:
  /// std::invalid_argument when options.max_range exceeds what centimetre
  /// coordinates in 16 bits hold (300 m).
  MapScanStore(SemanticMapOptions options, std::size_t frame_step);
  /// Scan k of the run (0 = first processed frame); kept when k is a multiple of the step.
  void offer(std::size_t k, const LabelledCloud& scan);
  /// The map with lidar_poses[k] for scan k (poses of the whole run).
  [[nodiscard]] LabelledCloud build(const std::vector<Pose>& lidar_poses, bool show_progress = true) const;
  [[nodiscard]] std::size_t bytes() const;

 private:
  struct CompactPoint {
    std::int16_t x, y, z;  ///< [cm], sensor frame
    std::uint16_t label;
    std::uint8_t remission;  ///< 0..255 for 0..1
  };
  SemanticMapOptions options_;
  std::size_t frame_step_;
  std::vector<std::size_t> frames_;
  std::vector<std::vector<CompactPoint>> scans_;
};

}  // namespace saloam
