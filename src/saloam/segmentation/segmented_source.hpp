#pragma once
// The segmentation stage of a frame's path (docs/architecture.md): a
// FrameSource that serves the scans of the source it wraps with every point
// labelled by a Segmenter (the paper's Fig. 2: raw point cloud P -> semantic
// cloud S). Worker threads segment ahead of the consumer, so the odometry
// does not wait for the network while there are frames to register; each
// scan is segmented by one worker on one thread, so the labels do not depend
// on the number of workers. A stream: each frame is served once, in order.
// Over a live source the workers take its frames as they come (next_frame),
// one reader at a time, and the stream ends where the live source's does.

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "saloam/io/frame_source.hpp"
#include "saloam/segmentation/segmenter.hpp"

namespace saloam {

/// What the stage needs: the model, the plugin that runs it, how rings are
/// recovered (the run's feature settings) and how many scans are segmented
/// at once and ahead.
struct SegmentationStageOptions {
  SegmenterSpec model;
  std::filesystem::path plugin;
  FeatureConfig rings;
  int workers = 1;
  std::size_t lookahead = 4;
};

class SegmentedSource final : public FrameSource {
 public:
  /// Opens one Segmenter per worker (a model that cannot be loaded fails
  /// here, before the run starts). InputError as Segmenter's.
  SegmentedSource(std::unique_ptr<FrameSource> inner, const SegmentationStageOptions& options);
  /// With Segmenters made by `make` (tests, the trainer).
  SegmentedSource(std::unique_ptr<FrameSource> inner, const std::function<std::unique_ptr<Segmenter>()>& make,
                  int workers, std::size_t lookahead);
  ~SegmentedSource() override;
  SegmentedSource(const SegmentedSource&) = delete;
  SegmentedSource& operator=(const SegmentedSource&) = delete;

  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  /// Frame i with its predicted labels (instance ids 0): frames 0, 1, 2, ... in order.
  LabelledCloud scan(std::size_t i) override;
  /// The same with its time; none past the inner source's last frame.
  std::optional<SourceFrame> next_frame(std::size_t i) override;
  [[nodiscard]] std::optional<StreamStats> stream_stats() const override { return inner_->stream_stats(); }
  void close_stream() override { inner_->close_stream(); }
  /// The inner source's stage times and this stage's ("segmentation": the
  /// network stage per frame, wall and worker-thread CPU time).
  [[nodiscard]] std::vector<SourceStageTimes> stage_times() const override;

 private:
  void work(const Segmenter& segmenter);
  /// Frame i segmented (with its time), none past the end; waits for the workers.
  std::optional<SourceFrame> take(std::size_t i);

  std::unique_ptr<FrameSource> inner_;
  SourceInfo info_;
  std::size_t lookahead_;
  std::vector<std::unique_ptr<Segmenter>> segmenters_;
  std::vector<std::thread> workers_;

  std::mutex read_mutex_;  ///< one worker reads the inner source at a time, frames in order
  mutable std::mutex mutex_;
  std::condition_variable ready_, room_;
  bool stopping_ = false;
  std::size_t next_read_ = 0;  ///< the frame a worker takes next
  std::size_t next_out_ = 0;   ///< the frame scan() must be asked for next
  std::optional<std::size_t> end_;  ///< the inner source's frame count, once a read found its end
  std::map<std::size_t, std::pair<SourceFrame, StageTime>> done_;  ///< segmented frames and their stage times
  std::vector<StageTime> served_;
  std::exception_ptr error_;
};

}  // namespace saloam
