#pragma once
// `saloam segment`: labels the scans of a source with the segmentation stage
// and writes them as SemanticKITTI .label files (NNNNNN.label, the scan's
// number; class in the low 16 bits, instance 0), which any run reads back
// with --labels DIR. When ground-truth labels are at hand, the predictions
// are scored against them (per-class IoU, SemanticKITTI's mIoU).

#include <cstddef>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include "saloam/runs/segmented_source.hpp"
#include "saloam/sim/label_noise.hpp"

namespace saloam {

struct SegmentRunOptions {
  std::size_t first_frame = 0;
  std::size_t end_frame = std::numeric_limits<std::size_t>::max();  ///< exclusive, clipped to the source
  /// A folder of ground-truth .label files to score against (none: no score).
  std::optional<std::filesystem::path> truth;
  /// Frame drawn as a range image coloured by predicted class (none: the middle frame).
  std::optional<std::size_t> picture_frame;
  bool show_progress = true;
};

struct SegmentRunResult {
  std::size_t frames = 0;
  std::size_t points = 0;
  std::vector<double> segment_ms;       ///< per frame: the network stage's wall time
  std::optional<SegmentationScore> score;
  std::filesystem::path picture;
  bool interrupted = false;
};

/// Segments frames [first_frame, end_frame) of `source` into `out_dir`
/// (created; it must not be the source's own labels folder).
SegmentRunResult run_segmentation(SegmentedSource& source, const std::filesystem::path& out_dir,
                                  const SegmentRunOptions& options);

}  // namespace saloam
