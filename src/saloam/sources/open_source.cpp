#include "saloam/sources/open_source.hpp"

#include "saloam/core/error.hpp"
#include "saloam/io/sequence_source.hpp"

namespace saloam {

std::unique_ptr<FrameSource> open_reader(const std::filesystem::path& path, const SourceOptions& options) {
  SequenceOptions sequence;
  sequence.labels_dir = options.labels;
  sequence.ignore_labels = options.ignore_labels || options.segmentation.has_value();
  auto source = std::make_unique<SequenceFolderSource>(SequenceReader(path, sequence), !options.ignore_calib);
  if (!options.ignore_calib && !source->info().velo_to_cam) {
    throw InputError(path / "calib.txt",
                     "not found: needed for poses in KITTI's camera frame, comparable with the ground truth; pass "
                     "--no-calib to work in the LiDAR frame (pose files hold LiDAR-frame poses, poses.txt is taken "
                     "as given)");
  }
  return source;
}

std::unique_ptr<FrameSource> add_stages(std::unique_ptr<FrameSource> source, const SourceOptions& options) {
  if (options.frames.first > 0 || options.frames.end < source->size()) {
    source = std::make_unique<FrameRangeSource>(std::move(source), options.frames);
  }
  if (options.segmentation) source = std::make_unique<SegmentedSource>(std::move(source), *options.segmentation);
  return source;
}

std::unique_ptr<FrameSource> open_source(const std::filesystem::path& path, const SourceOptions& options) {
  return add_stages(open_reader(path, options), options);
}

}  // namespace saloam
