#pragma once
// Runs the odometry over a sequence folder and writes its results as it goes:
//   poses.txt      KITTI format, camera-frame convention of the ground truth
//                  (P_i = Tr Q_i Tr^-1), so `saloam eval`, the KITTI devkit and evo read it;
//                  LiDAR-frame poses when the sequence has no calib.txt
//   poses_tum.txt  LiDAR-frame poses Q_i = T_L0<-Li with timestamps (TUM)
//   timing.json    per-stage timings
// Each pose line is flushed as soon as it is computed: an interrupted run
// (Ctrl-C) keeps every frame it finished.

#include <cstddef>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/odometry/semantic_odometry.hpp"

namespace saloam {

struct OdometryRunOptions {
  std::size_t first_frame = 0;
  std::size_t end_frame = std::numeric_limits<std::size_t>::max();  ///< exclusive, clipped to the sequence
  bool show_progress = true;
  std::string progress_label = "odom";
  bool no_calib = false;  ///< LiDAR-frame poses.txt, calib.txt not needed (output_velo_to_cam)
};

struct OdometryRunResult {
  std::vector<Pose> lidar_poses;     ///< T_L0<-Li (world = first processed scan)
  std::vector<Pose> output_poses;    ///< as written to poses.txt
  std::vector<double> timestamps;
  std::vector<FrameTimings> timings;
  std::size_t frames = 0;
  std::size_t registration_failures = 0;
  bool camera_frame = false;         ///< poses.txt uses the camera convention
  bool interrupted = false;
  [[nodiscard]] double median_frame_ms() const;
  [[nodiscard]] double worst_frame_ms() const;
};

/// Runs SemanticOdometry over frames [first_frame, end_frame) of `reader`,
/// writing into `out_dir` (created).
OdometryRunResult run_odometry(const SequenceReader& reader, const OdometryConfig& config,
                               const std::filesystem::path& out_dir, const OdometryRunOptions& options = {});

/// timing.json: frames, Hz (median, worst frame) and mean/median/max per stage.
void write_timing_json(const std::filesystem::path& file, const std::vector<FrameTimings>& timings);

}  // namespace saloam
