#pragma once
// Runs the whole SLAM system over a frame source and writes its results:
//   poses.txt, poses_tum.txt                    after loop closure (KITTI camera frame / TUM LiDAR frame)
//   poses_odometry.txt, poses_odometry_tum.txt  odometry only, flushed frame by frame
//   loops.csv        every verified candidate: scores, fit, decision, relative pose (and its truth with GT)
//   graph_map.json   the keyframes' semantic graphs with their optimised poses (when SGPR built them)
//   map.ply, map.png the global semantic map rebuilt from the optimised poses, with the loop edges
//   trajectories.png odometry, loop-closed and (when known) ground-truth trajectories
//   timing.json      per-stage timings, Hz, memory
//   cross_session.csv  with a map to join (SlamRunOptions::join_map): every
//                    verified cross-session candidate and confirming fit
//   eval_odometry.{json,png}, eval_slam.{json,png}  with SEQ/poses.txt
//     (loops are judged against SEQ/poses_sensor.txt when a simulated sequence has it)
//   summary.json     written last: where the frames came from (sequence,
//                    first_frame), loops and evaluation, whether the run was
//                    interrupted, and every file the run wrote
// Each file is put in place only when complete (core/output_file.hpp), and
// the folder holds no earlier run's files (core/output_folder.hpp). Ctrl-C
// ends the frame loop; everything above but the map is still written for
// the frames processed, and summary.json says "interrupted": true.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/core/output_folder.hpp"
#include "saloam/core/types.hpp"
#include "saloam/eval/trajectory_metrics.hpp"
#include "saloam/io/frame_source.hpp"
#include "saloam/maps/prior_map.hpp"
#include "saloam/runs/finished_frame.hpp"
#include "saloam/runs/loop_truth.hpp"
#include "saloam/slam/slam_system.hpp"

namespace saloam {

struct SlamRunOptions {
  bool show_progress = true;
  bool write_map = true;  ///< map.ply / map.png (re-reads the scans, or keeps copies of a stream's)
  /// Called with every frame after the SLAM has processed it (e.g. to run a
  /// second odometry on the same stream, or the live viewer).
  FrameFollower follow;
  /// Where to save the map for later runs (`--save-map`, maps/map_format.hpp);
  /// none: no map is saved. Not saved when the run is interrupted.
  std::optional<std::filesystem::path> save_map;
  std::string sensor;  ///< the sensor profile's name, recorded in the saved map
  /// A map this run joins (`slam --map`, maps/session_join.hpp): after the
  /// frames, the run's keyframes are joined to it; when linked, poses.txt
  /// and the map outputs are in its frame, and save_map (required) holds
  /// both sessions. cross_session.csv lists the verified cross-session fits.
  const PriorMap* join_map = nullptr;
};

struct SlamRunResult {
  std::size_t frames = 0;
  std::size_t keyframes = 0;
  std::size_t loops_accepted = 0;
  std::size_t loops_verified = 0;
  std::size_t registration_failures = 0;  ///< odometry frames that kept the prediction (RegistrationHealth)
  std::size_t degenerate_frames = 0;      ///< odometry frames with unconstrained directions (RegistrationHealth)
  GravityReport gravity;                  ///< which way was up, and from what
  bool interrupted = false;
  std::vector<std::string> files;    ///< written into the output folder, in order (summary.json last)
  double seconds = 0;                ///< wall time of the frame loop
  double median_frame_ms = 0;        ///< odometry + loop closure
  double mean_loop_ms = 0;           ///< loop closure's share per frame, amortised
  double peak_rss_mib = 0;
  std::optional<TrajectoryEvaluation> odometry_evaluation, slam_evaluation;
  std::optional<LoopSummary> loop_summary;
  std::string loop_reference;  ///< file the loops were judged against: poses_sensor.txt when present, else poses.txt
  std::optional<LoopSummary> loop_summary_poses_txt;  ///< against poses.txt, when poses_sensor.txt was used
  std::optional<std::uintmax_t> map_bytes;  ///< size of the saved map on disk (when one was saved)
  double map_save_seconds = 0;
  std::size_t map_keyframes = 0;  ///< keyframes of the saved map (both sessions' when joined)
  std::string join;  ///< what joining join_map did (describe_join; empty when none)
};

/// Loads the SGPR network when the configured detector needs one, from the
/// config's loop.sgpr_model; ConfigError when it is not set.
std::optional<SgprNetwork> load_loop_network(const SaloamConfig& config);

/// What run_slam() may write into its folder.
inline const std::vector<std::string> kSlamOutputs{
    "poses.txt",     "poses_tum.txt",   "poses_odometry.txt", "poses_odometry_tum.txt", "loops.csv",
    "graph_map.json", "map.ply",        "map.png",            "trajectories.png",       "timing.json",
    "eval_odometry.json", "eval_odometry.png", "eval_slam.json", "eval_slam.png", "cross_session.csv", "summary.json", "view.html"};

/// The output folder of a SLAM run over `source` (open_run_folder()).
OutputFolder open_slam_folder(const std::filesystem::path& out_dir, const SourceInfo& source);

/// Runs SlamSystem over every frame of `source`, writing into `folder`
/// (held by the caller, e.g. to add the viewer page under the same lock).
SlamRunResult run_slam(FrameSource& source, const SaloamConfig& config, std::optional<SgprNetwork> network,
                       OutputFolder& folder, const SlamRunOptions& options = {});
/// The same, in a folder of its own (open_slam_folder()).
SlamRunResult run_slam(FrameSource& source, const SaloamConfig& config, std::optional<SgprNetwork> network,
                       const std::filesystem::path& out_dir, const SlamRunOptions& options = {});

}  // namespace saloam
