#pragma once
// The one place where a command opens the frames it runs on: the reader for
// a path, then the stages every frame goes through before a run sees it.
//   reader   a SemanticKITTI sequence folder (SequenceFolderSource)
//   stages   the frame range (--frames A:B, FrameRangeSource), then the
//            segmentation (--segment: labels from a network, SegmentedSource)
// A new reader is one more case in open_reader(); a new stage wraps the
// source in add_stages(), in the order frames should pass it, with its
// option in SourceOptions. The simulator is no path: the demo builds its
// SimulatedSource itself and hands it to add_stages().

#include <filesystem>
#include <memory>
#include <optional>

#include "saloam/core/frame_range.hpp"
#include "saloam/io/frame_source.hpp"
#include "saloam/segmentation/segmented_source.hpp"

namespace saloam {

struct SourceOptions {
  /// --labels: .label files from this folder instead of the sequence's labels/.
  std::optional<std::filesystem::path> labels;
  /// Frames without labels (--no-semantics, label-agnostic loop detectors).
  bool ignore_labels = false;
  /// --no-calib: calib.txt is not read; the run works in the LiDAR frame
  /// (pose files hold LiDAR-frame poses, poses.txt is taken as such).
  bool ignore_calib = false;
  FrameRange frames;  ///< --frames A:B; everything by default
  /// --segment: every scan labelled by this model (the reader's labels are not read).
  std::optional<SegmentationStageOptions> segmentation;
};

/// The reader for `path`. A SemanticKITTI folder needs calib.txt unless
/// ignore_calib: without Tr a run's poses.txt could not be compared with the
/// ground truth (InputError naming --no-calib). Reader errors are
/// InputErrors naming the file.
std::unique_ptr<FrameSource> open_reader(const std::filesystem::path& path, const SourceOptions& options);

/// `source` behind the stages `options` asks for: the frame range
/// (ConfigError when it holds no frame), then the segmentation (InputError
/// when its model cannot be opened).
std::unique_ptr<FrameSource> add_stages(std::unique_ptr<FrameSource> source, const SourceOptions& options);

/// add_stages(open_reader(path, options), options).
std::unique_ptr<FrameSource> open_source(const std::filesystem::path& path, const SourceOptions& options);

}  // namespace saloam
