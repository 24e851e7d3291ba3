#pragma once
// A picture of a (simulated or real) SemanticKITTI sequence for judging it by
// eye: a top-down map of all scans accumulated with the ground-truth poses,
// coloured by class with the trajectory drawn. A scan's range image is
// viz/range_image.hpp.

#include <cstddef>
#include <filesystem>

#include "saloam/core/types.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/mapping/map_render.hpp"

namespace saloam {

struct MapRenderOptions {
  /// Picture size and trajectory drawing (the renderer is mapping's TopDownCanvas).
  TopDownOptions picture{0.25, 3200, true};
  std::size_t frame_step = 0;      ///< use every n-th scan (0 = automatic, about 300 scans)
  double max_range = 60.0;         ///< ignore points further than this from the sensor
  bool show_progress = true;
  /// Undo the motion distortion of each scan with the poses (sweep of 0.1 s
  /// from behind, clockwise, as in KITTI and in `saloam simulate`).
  bool deskew = true;
};

struct MapRenderStats : TopDownStats {
  std::size_t scans_used = 0;
};

/// Top-down map of the sequence `reader` reads (it needs poses) written to
/// `png`: its scans with the reader's labels, de-skewed with the poses, drawn
/// into a TopDownCanvas (the highest point per pixel wins, so buildings and
/// trees show over the ground as in an aerial view).
MapRenderStats render_map(const SequenceReader& reader, const std::filesystem::path& png,
                          const MapRenderOptions& options = {});

}  // namespace saloam
