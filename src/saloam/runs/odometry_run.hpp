#pragma once
// Runs the odometry over a frame source and writes its results as it goes:
//   poses.txt      KITTI format, camera-frame convention of the ground truth
//                  (P_i = Tr Q_i Tr^-1), so `saloam eval`, the KITTI devkit and evo read it;
//                  LiDAR-frame poses when the source has no Tr (--no-calib)
//   poses_tum.txt  LiDAR-frame poses Q_i = T_L0<-Li with timestamps (TUM)
//   timing.json    per-stage timings
//   summary.json   where the frames came from (sequence, first_frame), the
//                  counts, whether the run was interrupted, and the files written
// Each pose line is flushed as soon as it is computed, under a temporary
// name; the files are put in place when the frames are done: an interrupted
// run (Ctrl-C) keeps every frame it finished, a failed one leaves no pose file.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/io/frame_source.hpp"
#include "saloam/odometry/semantic_odometry.hpp"
#include "saloam/runs/finished_frame.hpp"
#include "saloam/runs/trajectory_writer.hpp"

namespace saloam {

struct OdometryRunOptions {
  bool show_progress = true;
  std::string progress_label = "odom";
  /// Called with every frame after the odometry has registered it (e.g. the live viewer).
  FrameFollower follow;
};

/// The configuration with up from the source's own IMU (SourceInfo::imu_up),
/// when it has one: odometry/gravity.hpp ranks it after a given mount.
OdometryConfig with_source_up(OdometryConfig config, const SourceInfo& info);
SaloamConfig with_source_up(SaloamConfig config, const SourceInfo& info);

/// What summary.json says of up ("gravity": up, source, tilt, votes, spread).
nlohmann::json gravity_json(const GravityReport& gravity);

/// How the frames' registrations went: failures (too few correspondences:
/// the frame kept the prediction) and degenerate frames (some directions
/// unconstrained: the prediction held those), counted and warned about as
/// they happen; both runs (odom, slam) report them in summary.json.
class RegistrationHealth {
 public:
  /// Looks at the registration of the frame `odometry` processed last
  /// (frame number `frame` of the source, for the warning); false when it failed.
  bool note(const SemanticOdometry& odometry, std::size_t frame);
  [[nodiscard]] std::size_t failures() const { return failures_; }
  [[nodiscard]] std::size_t degenerate_frames() const { return degenerate_frames_; }

 private:
  std::size_t failures_ = 0;
  std::size_t degenerate_frames_ = 0;
  bool in_degenerate_stretch_ = false;
};

struct OdometryRunResult {
  std::vector<Pose> lidar_poses;     ///< T_L0<-Li (world = first processed scan)
  std::vector<Pose> output_poses;    ///< as written to poses.txt
  std::vector<double> timestamps;
  std::vector<FrameTimings> timings;
  std::size_t frames = 0;
  std::size_t registration_failures = 0;
  std::size_t degenerate_frames = 0;  ///< RegistrationHealth
  GravityReport gravity;             ///< which way was up, and from what
  bool camera_frame = false;         ///< poses.txt uses the camera convention
  bool interrupted = false;
  std::vector<std::string> files;    ///< written into the output folder, in order
  [[nodiscard]] double median_frame_ms() const;
  [[nodiscard]] double worst_frame_ms() const;
};

/// An odometry run fed scan by scan: registers each scan and writes its pose
/// to poses.txt / poses_tum.txt in `out_dir` (which must exist) as it goes.
/// run_odometry() feeds it a source; a run that consumes a source itself
/// feeds it the same scans (the demo's label-agnostic baseline beside its SLAM).
class OdometryRun {
 public:
  /// `growing`: pose files written in place as they grow (a live source's run, TrajectoryWriter).
  OdometryRun(const OdometryConfig& config, const std::filesystem::path& out_dir, std::optional<Pose> velo_to_cam,
              bool growing = false);
  /// Registers the next scan and writes its pose; false when the
  /// registration failed (too few correspondences: the prediction was kept).
  /// Failures and degenerate frames are counted and warned about, named by
  /// `frame` (the source's frame number).
  bool add(const LabelledCloud& scan, double time, std::size_t frame);
  /// Puts the pose files in place (TrajectoryWriter::commit).
  void commit();
  [[nodiscard]] const SemanticOdometry& odometry() const { return odometry_; }
  [[nodiscard]] const OdometryRunResult& result() const { return result_; }

 private:
  SemanticOdometry odometry_;
  TrajectoryWriter writer_;
  OdometryRunResult result_;
  RegistrationHealth health_;
};

/// What run_odometry() may write into its folder.
inline const std::vector<std::string> kOdometryOutputs{"poses.txt", "poses_tum.txt", "timing.json", "summary.json"};

/// Runs SemanticOdometry over every frame of `source`, writing into `out_dir`
/// (open_run_folder(): held by this run alone, never the source's folder),
/// then timing.json and summary.json.
OdometryRunResult run_odometry(FrameSource& source, const OdometryConfig& config, const std::filesystem::path& out_dir,
                               const OdometryRunOptions& options = {});

/// The warning of a semantic run over a source without labels, naming --segment, --labels and --no-semantics.
void warn_no_labels(const SourceInfo& info);

/// timing.json: frames, Hz (median, worst frame) and mean/median/max per
/// stage, with the source's stages (e.g. segmentation) beside the odometry's.
void write_timing_json(const std::filesystem::path& file, const std::vector<FrameTimings>& timings,
                       const std::vector<SourceStageTimes>& source_stages = {});

}  // namespace saloam
