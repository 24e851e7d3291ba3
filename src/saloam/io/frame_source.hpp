#pragma once
// Where a run's frames come from. Every run (odometry, SLAM, place
// evaluation, bench, demo) reads its frames through one FrameSource: a
// reader of recorded data (SequenceFolderSource here: a SemanticKITTI folder;
// the other layouts' readers in sources/: KITTI raw drives, PCD and PLY
// folders, ROS bags, sensor packet captures), the simulator rendering in memory (SimulatedSource,
// sim/), or a stage that wraps another source and changes what it serves
// (FrameRangeSource below).
// Runs see only this interface; sources/open_source.hpp picks the reader for
// a path and puts the stages in front of it.
//
// What every source promises:
//  - info() is known before the first scan and does not change;
//  - frames are numbered 0 .. size()-1, and info().times holds one
//    increasing timestamp [s] per frame (the number of frames is its size);
//  - scan(i) is frame i in its sensor (LiDAR) frame; its points carry classes
//    (cloud.has_labels) exactly when info().has_labels;
//  - a rereadable source serves any frame, any number of times, in any
//    order; a stream (rereadable false) serves frames 0, 1, 2, ... once
//    each, in that order (std::logic_error otherwise);
//  - a live source (info().live: frames made as a sensor's packets arrive)
//    knows neither its frames nor their times beforehand: info().times is
//    empty, and it serves its frames only through next_frame(), which waits
//    for the next one and says when the stream ended; stream_stats() counts
//    what it received, served and dropped. Runs read every source through
//    next_frame(), so that they take both kinds;
//  - velo_to_cam, camera_poses and sensor_camera_poses are there when known;
//    pose lists hold one pose per frame, not re-based: in the KITTI camera
//    convention of poses.txt (P_i = Tr Q_i Tr^-1) when velo_to_cam is known,
//    else LiDAR-frame poses Q_i = T_L0<-Li (a source without calibration runs
//    in the LiDAR frame).
//
// A stage (decorator) owns the source it wraps, starts from a copy of its
// info and changes what it changes: FrameRangeSource the frames, times,
// poses and first_frame; a segmentation stage would set has_labels and serve
// scans with predicted labels.

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saloam/core/frame_range.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/core/types.hpp"

namespace saloam {

/// What a source holds, known before its first scan.
struct SourceInfo {
  std::string name;            ///< for messages: the folder, or what is simulated
  std::vector<double> times;   ///< [s] one per frame, increasing
  bool has_labels = false;     ///< scans carry per-point classes
  bool rereadable = true;      ///< false: a stream (see above)
  bool live = false;           ///< frames arrive as the run goes (see above): times empty, size() 0
  std::optional<Pose> velo_to_cam;                ///< Tr, velodyne to camera 0, when known
  /// Reference poses (poses.txt; a KITTI raw drive's GPS/INS), when known; frame as said above.
  std::optional<std::vector<Pose>> camera_poses;
  /// Where the scans were really taken, when that differs from camera_poses
  /// (a simulated sequence whose given heights did not fit its ground).
  std::optional<std::vector<Pose>> sensor_camera_poses;
  /// The sequence folder the scans are read from, if any: a run never writes
  /// its results there, and outputs refer back to it (the viewer reads the scans).
  std::optional<std::filesystem::path> folder;
  /// Frame i is the folder's (or the recording's) frame first_frame + i (after `--frames A:B`: A).
  std::size_t first_frame = 0;
  /// The layout read, as --format names it ("semantickitti", "kitti-raw",
  /// "pcd", "ply", "rosbag", "rosbag2", "mcap", "pcap"), or "simulated".
  std::string format;
  /// The point fields of the scans as the source names them ("x y z
  /// intensity ring t"; KITTI .bin scans: "x y z remission"), from the first
  /// scan's header.
  std::string point_fields;
  /// Where the times, the calibration and the reference come from, one line
  /// each ("times: times.txt", "reference: oxts/ (GPS/INS) ..."): what
  /// `saloam info` shows beside the numbers.
  std::vector<std::string> notes;
  /// Up (against gravity, unit) in the scans' frame from the sensor's own
  /// IMU, when the source has one and it was still at the start: the mean
  /// of its accelerometer over the still samples (odometry/gravity.hpp).
  std::optional<Eigen::Vector3d> imu_up;

  [[nodiscard]] std::size_t size() const { return times.size(); }
};

/// The time a stage spent on each frame it served (in the order served),
/// for timing reports.
struct SourceStageTimes {
  std::string name;                 ///< e.g. "segmentation"
  std::vector<StageTime> per_frame;
};

/// A frame with its time, as next_frame() serves it.
struct SourceFrame {
  LabelledCloud cloud;
  double time = 0.0;  ///< [s]
};

/// What a live source received and did with it, for the run's log and summary.
struct StreamStats {
  std::string address;             ///< where it listened: "udp://0.0.0.0:7502"
  std::size_t packets = 0;         ///< datagrams received
  std::string packet_counts;       ///< the decoder's: "1234 data packets, 0 malformed, ..."
  std::size_t frames_made = 0;     ///< whole frames assembled from the packets
  std::size_t frames_served = 0;   ///< handed to the run
  std::size_t frames_dropped = 0;  ///< whole frames dropped because the run fell behind (queue full)
  std::size_t frames_out_of_order = 0;  ///< dropped because their time was not after the last one's
  std::size_t frames_incomplete = 0;    ///< dropped whole because packets of theirs never arrived
  std::size_t frames_unread = 0;   ///< still queued when the run ended (Ctrl-C, frame limit)
  std::string ended_by;            ///< "idle for 2 s", "interrupted", "" while running
  /// [ms] from the packet that completed a frame to the run asking for the
  /// next frame (its pose written; with --segment, the segmentation stage
  /// asking, which it does ahead of the run), per served frame whose next
  /// was asked for.
  std::vector<double> latency_ms;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  [[nodiscard]] virtual const SourceInfo& info() const = 0;
  /// Frame i < size(), as promised above.
  virtual LabelledCloud scan(std::size_t i) = 0;
  /// The times of the stages that prepared the frames served so far (a
  /// stage adds its own to those of the source it wraps); none for a reader.
  [[nodiscard]] virtual std::vector<SourceStageTimes> stage_times() const { return {}; }
  /// Frame i with its time, i being the number of frames read so far
  /// through it; none when the source has no frame i: i >= size() for a
  /// recorded source, the stream ended for a live one (no packet within its
  /// idle timeout, or Ctrl-C). The default serves scan(i) and info().times[i].
  virtual std::optional<SourceFrame> next_frame(std::size_t i);
  /// A live source's counts (a stage passes its source's on); none otherwise.
  [[nodiscard]] virtual std::optional<StreamStats> stream_stats() const { return std::nullopt; }
  /// No frame will be asked for any more (a frame limit reached): a live
  /// source stops receiving, so that its counts are final (frames after the
  /// limit are not counted as dropped). Nothing for other sources.
  virtual void close_stream() {}

  [[nodiscard]] std::size_t size() const { return info().size(); }
};

/// Frames [first, end) of another source, numbered from 0: the stage behind
/// `--frames A:B`. Over a stream, the frames before `first` are read and
/// dropped when the first frame is asked for.
class FrameRangeSource final : public FrameSource {
 public:
  /// ConfigError when the range holds no frame of `inner`.
  FrameRangeSource(std::unique_ptr<FrameSource> inner, const FrameRange& range);

  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  LabelledCloud scan(std::size_t i) override;
  /// Over a live source: its frames first .. end-1 as they come (the
  /// frames before `first` read and dropped), then none: `--frames 0:N` is
  /// a live run's frame limit.
  std::optional<SourceFrame> next_frame(std::size_t i) override;
  [[nodiscard]] std::vector<SourceStageTimes> stage_times() const override { return inner_->stage_times(); }
  [[nodiscard]] std::optional<StreamStats> stream_stats() const override { return inner_->stream_stats(); }
  void close_stream() override { inner_->close_stream(); }

 private:
  std::unique_ptr<FrameSource> inner_;
  std::size_t first_ = 0;
  std::size_t end_ = 0;  ///< exclusive
  std::size_t dropped_ = 0;  ///< a stream's frames before first_ read so far
  SourceInfo info_;
};

}  // namespace saloam
