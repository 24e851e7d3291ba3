#pragma once
// `saloam segment`: writes the labels of a source's scans (a source whose
// last stage is the segmentation) as SemanticKITTI .label files
// (NNNNNN.label, the scan's number in its folder; class in the low 16 bits,
// instance 0), which any run reads back with --labels DIR. When ground-truth
// labels are at hand, the predictions are scored against them (per-class
// IoU, SemanticKITTI's mIoU).

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <vector>

#include "saloam/io/frame_source.hpp"
#include "saloam/eval/segmentation_score.hpp"

namespace saloam {

struct SegmentRunOptions {
  /// A folder of ground-truth .label files to score against (none: no score).
  std::optional<std::filesystem::path> truth;
  /// Frame (the folder's number) drawn as a range image coloured by predicted
  /// class (none: the middle frame of the source).
  std::optional<std::size_t> picture_frame;
  /// The picture's rows: beam elevations [deg], top first (viz/range_image.hpp).
  std::vector<double> picture_elevations_deg;
  bool show_progress = true;
};

struct SegmentRunResult {
  std::size_t frames = 0;
  std::size_t points = 0;
  std::vector<StageTime> segment_times;  ///< per frame: the segmentation stage's time
  std::optional<SegmentationScore> score;
  std::filesystem::path score_file;  ///< score.json beside the labels (when scored)
  std::filesystem::path picture;
  bool interrupted = false;
};

/// Writes the labels of every frame of `source` (which has labels) into
/// `out_dir` (created; never the source folder's own labels/ or labels_gt/),
/// and, when scored, `out_dir/score.json` (SegmentationScore::to_json with
/// the truth folder, the frames scored and whether the run was interrupted).
SegmentRunResult run_segmentation(FrameSource& source, const std::filesystem::path& out_dir,
                                  const SegmentRunOptions& options);

}  // namespace saloam
