#pragma once
// The segmentation stage of a run: a FrameSource that serves the scans of
// another source with every point labelled by a Segmenter (the paper's
// Fig. 2, raw point cloud P -> semantic cloud S). Worker threads segment
// ahead of the consumer, so the odometry does not wait for the network
// while it has frames to register; each scan is segmented by one worker on
// one thread, so the labels do not depend on the number of workers. A
// streaming source: each frame is served once, in increasing order.

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "saloam/runs/frame_source.hpp"
#include "saloam/segmentation/segmenter.hpp"

namespace saloam {

class SegmentedSource final : public FrameSource {
 public:
  /// One Segmenter per worker, made by `make_segmenter` here (so that a
  /// model that cannot be loaded fails before the run starts). `inner` must
  /// outlive the source; up to `lookahead` scans are segmented ahead.
  SegmentedSource(FrameSource& inner, const std::function<std::unique_ptr<Segmenter>()>& make_segmenter, int workers,
                  std::size_t lookahead);
  ~SegmentedSource() override;
  SegmentedSource(const SegmentedSource&) = delete;
  SegmentedSource& operator=(const SegmentedSource&) = delete;

  [[nodiscard]] std::string name() const override { return inner_.name(); }
  [[nodiscard]] std::size_t size() const override { return inner_.size(); }
  [[nodiscard]] bool has_labels() const override { return true; }
  [[nodiscard]] const std::vector<double>& times() const override { return inner_.times(); }
  [[nodiscard]] std::optional<Pose> velo_to_cam() const override { return inner_.velo_to_cam(); }
  [[nodiscard]] std::optional<std::vector<Pose>> camera_poses() const override { return inner_.camera_poses(); }
  [[nodiscard]] std::optional<std::vector<Pose>> sensor_camera_poses() const override {
    return inner_.sensor_camera_poses();
  }
  [[nodiscard]] std::optional<std::filesystem::path> folder() const override { return inner_.folder(); }
  /// Frame i with its predicted labels (instance ids 0). The first call sets
  /// where the stream starts; later calls must ask for the next frame.
  LabelledCloud scan(std::size_t i) override;
  [[nodiscard]] bool rereadable() const override { return false; }

  /// Wall time [ms] the network stage took per frame served so far (in order).
  [[nodiscard]] std::vector<double> segment_ms() const;

 private:
  void work(const Segmenter& segmenter);

  FrameSource& inner_;
  std::size_t lookahead_;
  std::vector<std::unique_ptr<Segmenter>> segmenters_;
  std::vector<std::thread> workers_;

  mutable std::mutex mutex_;
  std::condition_variable ready_, room_;
  bool started_ = false;
  bool stopping_ = false;
  std::size_t next_read_ = 0;  ///< the frame a worker takes next
  std::size_t next_out_ = 0;   ///< the frame scan() must be asked for next
  std::map<std::size_t, std::pair<LabelledCloud, double>> done_;  ///< segmented frames and their time [ms]
  std::vector<double> served_ms_;
  std::exception_ptr error_;
};

}  // namespace saloam
