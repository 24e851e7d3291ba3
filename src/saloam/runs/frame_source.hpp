#pragma once
// Where a run's frames come from. A run (SLAM, odometry) reads labelled scans
// in order, their timestamps and, when known, the extrinsic Tr and the ground
// truth; it does not care whether they lie in a sequence folder or are
// rendered by the simulator as they are needed:
//   SequenceFolderSource   a SemanticKITTI sequence folder (SequenceReader)
//   SimulatedSource        the simulator, in memory: frames are rendered
//                          ahead on a worker thread while the run consumes
//                          them, and written to disk only when asked
// Frames are LiDAR scans in their sensor frame; poses are KITTI camera-frame
// poses as in poses.txt (P_i = Tr Q_i Tr^-1).

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/sim/label_noise.hpp"
#include "saloam/sim/simulator.hpp"

namespace saloam {

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  /// For messages: the folder, or what is simulated.
  [[nodiscard]] virtual std::string name() const = 0;
  [[nodiscard]] virtual std::size_t size() const = 0;
  [[nodiscard]] virtual bool has_labels() const = 0;
  [[nodiscard]] virtual const std::vector<double>& times() const = 0;
  /// Tr (velodyne to camera), when known.
  [[nodiscard]] virtual std::optional<Pose> velo_to_cam() const = 0;
  /// Ground truth (camera frame, poses.txt), when known.
  [[nodiscard]] virtual std::optional<std::vector<Pose>> camera_poses() const = 0;
  /// Where the scans were really taken, when that differs from camera_poses()
  /// (a simulated sequence whose given heights did not fit its ground).
  [[nodiscard]] virtual std::optional<std::vector<Pose>> sensor_camera_poses() const = 0;
  /// The folder the frames are read from, if any (an output must not overwrite it).
  [[nodiscard]] virtual std::optional<std::filesystem::path> folder() const = 0;

  /// Frame i. A streaming source (rereadable() false) serves each frame once,
  /// in increasing order.
  virtual LabelledCloud scan(std::size_t i) = 0;
  /// True when scan() may be called again for any frame (e.g. to build a map afterwards).
  [[nodiscard]] virtual bool rereadable() const = 0;
};

class SequenceFolderSource final : public FrameSource {
 public:
  /// Keeps a reference: `reader` must outlive the source.
  explicit SequenceFolderSource(const SequenceReader& reader) : reader_(reader) {}

  [[nodiscard]] std::string name() const override { return reader_.root().string(); }
  [[nodiscard]] std::size_t size() const override { return reader_.size(); }
  [[nodiscard]] bool has_labels() const override { return reader_.has_labels(); }
  [[nodiscard]] const std::vector<double>& times() const override { return reader_.times(); }
  [[nodiscard]] std::optional<Pose> velo_to_cam() const override;
  [[nodiscard]] std::optional<std::vector<Pose>> camera_poses() const override;
  /// SEQ/poses_sensor.txt when present (InputError when it does not match the scans).
  [[nodiscard]] std::optional<std::vector<Pose>> sensor_camera_poses() const override;
  [[nodiscard]] std::optional<std::filesystem::path> folder() const override { return reader_.root(); }
  LabelledCloud scan(std::size_t i) override { return reader_.load_scan(i); }
  [[nodiscard]] bool rereadable() const override { return true; }

 private:
  const SequenceReader& reader_;
};

/// Streams a SimulatedSequence: a worker thread renders up to `lookahead`
/// frames ahead of the consumer (the simulator's ray casting is the costly
/// part; it runs beside the consumer on another core). With `keep_folder`
/// the frames are also written there as a sequence folder, exactly as
/// `saloam simulate` would write them (trimmed to the frames rendered when
/// the run stops early). The worker stops when the source is destroyed; an
/// error on the worker is rethrown by scan().
class SimulatedSource final : public FrameSource {
 public:
  SimulatedSource(const SimulatedSequence& sequence, std::size_t lookahead = 8,
                  std::optional<std::filesystem::path> keep_folder = std::nullopt);
  ~SimulatedSource() override;
  SimulatedSource(const SimulatedSource&) = delete;
  SimulatedSource& operator=(const SimulatedSource&) = delete;

  [[nodiscard]] std::string name() const override;
  [[nodiscard]] std::size_t size() const override { return sequence_.size(); }
  [[nodiscard]] bool has_labels() const override { return true; }
  [[nodiscard]] const std::vector<double>& times() const override { return sequence_.times(); }
  [[nodiscard]] std::optional<Pose> velo_to_cam() const override { return sequence_.velo_to_cam(); }
  [[nodiscard]] std::optional<std::vector<Pose>> camera_poses() const override { return sequence_.camera_poses(); }
  [[nodiscard]] std::optional<std::vector<Pose>> sensor_camera_poses() const override;
  [[nodiscard]] std::optional<std::filesystem::path> folder() const override { return std::nullopt; }
  LabelledCloud scan(std::size_t i) override;
  [[nodiscard]] bool rereadable() const override { return false; }

  /// Scores of the emulated network labels over the frames rendered so far
  /// (noisy-label sequences); call after the run.
  [[nodiscard]] SegmentationScore label_score() const;
  [[nodiscard]] std::size_t frames_rendered() const;

 private:
  void render_ahead();
  void keep(std::size_t k, const SimulatedFrame& frame) const;
  void finish_kept_folder(std::size_t frames) const;

  const SimulatedSequence& sequence_;
  const std::size_t lookahead_;
  const std::optional<std::filesystem::path> keep_folder_;

  mutable std::mutex mutex_;
  std::condition_variable frame_ready_, slot_free_;
  std::deque<LabelledCloud> queue_;  ///< frames next_ ... next_ + queue_.size() - 1
  std::size_t next_ = 0;             ///< the frame scan() must be asked for next
  std::size_t rendered_ = 0;
  bool stopping_ = false;
  std::exception_ptr error_;
  SegmentationScore score_;
  std::thread worker_;
};

}  // namespace saloam
