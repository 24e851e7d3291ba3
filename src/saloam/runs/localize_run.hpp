#pragma once
// Localisation in a saved map over a frame source (maps/localizer.hpp), and
// its outputs:
//   poses.txt, poses_tum.txt  the placed frames only, in the map's frame (KITTI
//                             camera convention with the source's Tr / TUM LiDAR
//                             frame with timestamps); frames.csv says which
//   frames.csv                every frame: status (localized, odometry,
//                             unplaced), whether it was fitted to the map, metres
//                             since the last fit, the fit's inliers, position, events
//   relocalizations.csv       every verified candidate and confirming fix
//   timing.json               per-stage timings, Hz, memory, map cache
//   summary.json              written last: counts, where the run was first
//                             placed, the evaluation when the truth is known
// Files are put in place when complete (core/output_file.hpp), in a folder
// held by this run alone (core/output_folder.hpp).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/io/frame_source.hpp"
#include "saloam/maps/localizer.hpp"
#include "saloam/maps/prior_map.hpp"
#include "saloam/runs/finished_frame.hpp"

namespace saloam {

/// A map's own error against the truth of the run that made it.
struct MapError {
  /// The rigid transform that best aligns the map's keyframes with their
  /// truth (as the mapping run's ATE aligns).
  Pose alignment = Pose::Identity();
  /// [m] each keyframe's position error after the alignment (NaN: its
  /// session is not linked to the map frame).
  std::vector<double> keyframe_errors;
};

/// The map's error when the sources its sessions were made from hold
/// reference poses (read_sequence_truth: poses_sensor.txt or poses.txt,
/// calib.txt's Tr, a simulated pass's origin); none when one cannot be read
/// or its poses do not cover the keyframes.
std::optional<MapError> map_error_against_source(const PriorMap& map);

struct LocalizeRunOptions {
  bool show_progress = true;
  /// T_map<-L0: the map frame from the source's first frame (LiDAR), when
  /// known (simulated sessions of one world): poses are then checked against
  /// the source's reference poses in the map frame, and each relocalisation
  /// judged true or false (0.5 m, 2 degrees, as loops).
  std::optional<Pose> truth_map_from_source;
  /// The map's own error (map_error_against_source). Estimates are moved by
  /// its alignment before they are compared with the truth, so that the
  /// localisation error and the mapping ATE measure the same thing.
  std::optional<MapError> map_error;
  /// Called with every frame placed in the map (its pose in the map's frame),
  /// e.g. the live viewer; frames not placed are not followed.
  FrameFollower follow;
};

struct LocalizeRunResult {
  std::size_t frames = 0;
  std::size_t localized = 0, odometry = 0, unplaced = 0;
  std::optional<double> first_placed_m;  ///< [m] travelled when first placed
  std::optional<std::size_t> first_placed_frame;
  std::size_t hypotheses = 0, confirmed = 0, refuted = 0;
  std::size_t left_map = 0, reentered = 0;
  /// With the truth: relocalisations (confirmed) farther than 0.5 m / 2 deg
  /// from it, and the position errors of the placed frames in the map frame.
  std::optional<std::size_t> false_relocalizations;
  std::optional<double> localized_rmse_m, localized_max_m, placed_rmse_m;
  /// [m] RMSE over the localized frames of the map's own error where each is
  /// (its nearest map keyframe's, LocalizeRunOptions::map_error): what the
  /// localized error inherits from the map; the rest is the localisation's.
  std::optional<double> map_error_where_localized_m;
  /// With reference poses: ATE of the placed frames after an SE(3) alignment.
  std::optional<double> aligned_ate_m;
  double seconds = 0;
  double median_frame_ms = 0, mean_frame_ms = 0;
  double peak_rss_mib = 0;
  std::size_t map_loads = 0;
  bool interrupted = false;
  std::vector<std::string> files;
};

inline const std::vector<std::string> kLocalizeOutputs{"poses.txt", "poses_tum.txt", "frames.csv", "relocalizations.csv",
                                                       "timing.json", "summary.json"};

/// Runs a Localizer over every frame of `source` in `map`, writing into `out_dir`.
LocalizeRunResult run_localize(FrameSource& source, const SaloamConfig& config, const PriorMap& map,
                               std::optional<SgprNetwork> network, const std::filesystem::path& out_dir,
                               const LocalizeRunOptions& options = {});

}  // namespace saloam
