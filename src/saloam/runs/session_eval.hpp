#pragma once
// Per-session accuracy of a saved map (`saloam eval --map MAP --gt SEQ ...`,
// docs/map_format.md): each session's keyframes against the ground truth of
// the sequence it was made from, after one SE(3) alignment of every linked
// keyframe (the common frame's own error taken out once) and with none (the
// map frame is the LiDAR frame of session 0's first keyframe, as the truth's
// when rebased there); and the cross-session loop edges judged against the
// truth (0.5 m, 2 degrees, as loops are judged).
//
// The truths must share one world frame: a sequence written by `saloam
// simulate --passes ... --pass K` records its first frame's pose in that
// world (simulation.yaml "origin"); any other sequence's poses are taken as
// given in a frame common to all (sessions cut from one sequence).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "saloam/core/types.hpp"
#include "saloam/eval/trajectory_metrics.hpp"
#include "saloam/maps/map_format.hpp"

namespace saloam {

/// "origin" (the world pose of its first frame, T_world<-camera0 of the
/// route) and "passes" of a sequence written by `saloam simulate --passes`;
/// none when `folder` has no simulation.yaml or it records no passes.
struct SimulatedPass {
  Pose origin = Pose::Identity();
  std::string passes;
};
std::optional<SimulatedPass> read_simulated_pass(const std::filesystem::path& folder);

/// The LiDAR poses of sequence folder `folder` in the common world frame, one
/// per source frame: poses_sensor.txt (where the scans were taken) or
/// poses.txt, camera frame converted with calib.txt's Tr when there is one
/// (P = Tr^-1 Q Tr), rebased on the first pose and, for a simulated pass,
/// put at its origin. InputError naming the file when one cannot be read.
std::vector<Pose> read_sequence_truth(const std::filesystem::path& folder);

struct SessionErrors {
  std::size_t keyframes = 0;
  bool linked = true;     ///< false: in a frame of its own: left out, no errors
  ErrorStats aligned;     ///< [m] position error after the one alignment
  ErrorStats unaligned;   ///< [m] position error in the map frame
};

struct SessionEvaluation {
  std::vector<SessionErrors> sessions;
  ErrorStats all_aligned;              ///< every linked keyframe
  std::size_t true_cross_session_loops = 0;
  std::size_t false_cross_session_loops = 0;
};

/// The one SE(3) alignment of every linked keyframe's position to its truth
/// in the map frame (the LiDAR frame of session 0's first keyframe, as the
/// truth's when rebased there), and each keyframe's error.
struct KeyframeAlignment {
  Pose alignment = Pose::Identity();  ///< applied to the map's poses
  std::vector<double> aligned;        ///< [m] per keyframe, after it (NaN: session not linked)
  std::vector<double> unaligned;      ///< [m] per keyframe, in the map frame (NaN: session not linked)
  std::vector<Pose> world;            ///< each keyframe's truth in the world frame
};

/// `truth[s]`: session s's LiDAR poses in the common world frame, indexed by
/// source frame (MapSession::first_frame + the keyframe's frame), as
/// read_sequence_truth gives them. std::invalid_argument when the counts do
/// not fit (a session without a truth, a keyframe beyond its truth, fewer
/// than 3 linked keyframes).
KeyframeAlignment align_keyframes(const SavedMap& map, const std::vector<std::vector<Pose>>& truth);

/// align_keyframes' errors per session, and the cross-session loop edges
/// judged against the truth; the same exceptions.
SessionEvaluation evaluate_sessions(const SavedMap& map, const std::vector<std::vector<Pose>>& truth);

void print_session_evaluation(std::ostream& out, const SessionEvaluation& evaluation,
                              const std::vector<std::string>& truth_names);
nlohmann::json session_evaluation_json(const SessionEvaluation& evaluation, const std::vector<std::string>& truth_names);

}  // namespace saloam
