#include "saloam/runs/session_eval.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/runs/loop_truth.hpp"

namespace saloam {

namespace {
constexpr std::size_t kMaxRecordBytes = 1 << 16;
}  // namespace

std::optional<SimulatedPass> read_simulated_pass(const std::filesystem::path& folder) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(folder / "simulation.yaml", ec)) return std::nullopt;
  std::istringstream lines(read_file(folder / "simulation.yaml", kMaxRecordBytes, "simulation record"));
  SimulatedPass pass;
  bool origin = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.starts_with("passes: ")) pass.passes = line.substr(8);
    if (line.starts_with("origin: ")) {
      std::istringstream numbers(line.substr(8));
      double v[12];
      origin = true;
      for (double& x : v) origin = origin && static_cast<bool>(numbers >> x);
      if (origin) pass.origin = orthonormalized(pose_from_3x4(v));
    }
  }
  if (!origin || pass.passes.empty()) return std::nullopt;
  return pass;
}

std::vector<Pose> read_sequence_truth(const std::filesystem::path& folder) {
  const bool sensor = std::filesystem::is_regular_file(folder / "poses_sensor.txt");
  std::vector<Pose> truth = read_kitti_poses(folder / (sensor ? "poses_sensor.txt" : "poses.txt"));
  if (truth.empty()) throw InputError(folder / "poses.txt", "no poses");
  if (std::filesystem::is_regular_file(folder / "calib.txt")) {
    truth = camera_to_lidar_poses(truth, read_velo_to_cam(folder / "calib.txt"));
  }
  const std::optional<SimulatedPass> pass = read_simulated_pass(folder);
  // origin is the route's camera pose; in LiDAR terms the pass's first LiDAR
  // pose is origin's LiDAR counterpart, and the passes' relative pose
  // origin_a^-1 origin_b is taken as the LiDAR frames' (as `localize` does).
  const Pose world_from_first = pass ? pass->origin : Pose::Identity();
  const Pose rebase = truth.front().inverse();
  for (Pose& pose : truth) pose = orthonormalized(world_from_first * rebase * pose);
  return truth;
}

namespace {

// The truth of each keyframe (world frame); throws when one is missing.
std::vector<Pose> keyframe_truth(const SavedMap& map, const std::vector<MapSession>& sessions,
                                 const std::vector<std::vector<Pose>>& truth) {
  if (truth.size() != sessions.size()) {
    throw std::invalid_argument(fmt::format("the map has {} sessions, {} ground truths given", sessions.size(), truth.size()));
  }
  std::vector<Pose> out;
  for (const MapKeyframe& kf : map.keyframes) {
    const std::uint64_t frame = sessions[kf.session].first_frame + kf.frame;
    if (frame >= truth[kf.session].size()) {
      throw std::invalid_argument(fmt::format("session {}'s keyframe at source frame {} has no ground truth ({} poses)",
                                              kf.session, frame, truth[kf.session].size()));
    }
    out.push_back(truth[kf.session][frame]);
  }
  return out;
}

}  // namespace

KeyframeAlignment align_keyframes(const SavedMap& map, const std::vector<std::vector<Pose>>& truth) {
  const std::vector<MapSession> sessions = map_sessions(map);
  KeyframeAlignment out;
  out.world = keyframe_truth(map, sessions, truth);
  // The map frame: the LiDAR frame of session 0's first keyframe.
  const Pose map_from_world = out.world.front().inverse();
  std::vector<Eigen::Vector3d> estimated, reference, linked_estimated, linked_reference;
  for (std::size_t k = 0; k < map.keyframes.size(); ++k) {
    estimated.push_back(map.keyframes[k].pose.translation());
    reference.push_back((map_from_world * out.world[k]).translation());
    if (!sessions[map.keyframes[k].session].linked) continue;
    linked_estimated.push_back(estimated.back());
    linked_reference.push_back(reference.back());
  }
  if (linked_estimated.size() < 3) throw std::invalid_argument("fewer than 3 linked keyframes: nothing to align");
  const SimilarityTransform s = umeyama_alignment(linked_estimated, linked_reference, false);
  out.alignment.linear() = s.rotation;
  out.alignment.translation() = s.translation;
  for (std::size_t k = 0; k < map.keyframes.size(); ++k) {
    const bool linked = sessions[map.keyframes[k].session].linked;
    out.aligned.push_back(linked ? (out.alignment * estimated[k] - reference[k]).norm() : NAN);
    out.unaligned.push_back(linked ? (estimated[k] - reference[k]).norm() : NAN);
  }
  return out;
}

SessionEvaluation evaluate_sessions(const SavedMap& map, const std::vector<std::vector<Pose>>& truth) {
  const std::vector<MapSession> sessions = map_sessions(map);
  const KeyframeAlignment alignment = align_keyframes(map, truth);
  std::vector<std::vector<double>> aligned(sessions.size()), unaligned(sessions.size());
  std::vector<double> all;
  for (std::size_t k = 0; k < map.keyframes.size(); ++k) {
    const std::uint32_t session = map.keyframes[k].session;
    if (!sessions[session].linked) continue;
    aligned[session].push_back(alignment.aligned[k]);
    unaligned[session].push_back(alignment.unaligned[k]);
    all.push_back(alignment.aligned[k]);
  }
  SessionEvaluation out;
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    out.sessions.push_back({sessions[i].keyframes, sessions[i].linked, error_stats(aligned[i]), error_stats(unaligned[i])});
  }
  out.all_aligned = error_stats(all);
  const std::vector<Pose>& world = alignment.world;
  for (const PoseGraphEdge& e : map.edges) {
    if (e.kind != EdgeKind::kLoop || map.keyframes[e.from].session == map.keyframes[e.to].session) continue;
    const bool ok = agrees_with_truth(e.measured, world[e.from].inverse() * world[e.to]);
    ++(ok ? out.true_cross_session_loops : out.false_cross_session_loops);
  }
  return out;
}

void print_session_evaluation(std::ostream& out, const SessionEvaluation& ev, const std::vector<std::string>& names) {
  out << "## Per-session keyframe position error\n\n"
      << "| session | ground truth | keyframes | RMSE / max, one SE(3) alignment [m] | RMSE / max, map frame [m] |\n"
      << "|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < ev.sessions.size(); ++i) {
    const SessionErrors& s = ev.sessions[i];
    const std::string name = i < names.size() ? names[i] : "";
    if (!s.linked) {
      out << fmt::format("| {} | {} | {} | not linked | not linked |\n", i, name, s.keyframes);
      continue;
    }
    out << fmt::format("| {} | {} | {} | {:.3f} / {:.3f} | {:.3f} / {:.3f} |\n", i, name, s.keyframes, s.aligned.rmse,
                       s.aligned.max, s.unaligned.rmse, s.unaligned.max);
  }
  out << fmt::format("\nAll linked keyframes ({}): RMSE {:.3f} m after the alignment. Cross-session loop edges: {} true, "
                     "{} false (0.5 m, 2 degrees).\n",
                     ev.all_aligned.count, ev.all_aligned.rmse, ev.true_cross_session_loops, ev.false_cross_session_loops);
}

nlohmann::json session_evaluation_json(const SessionEvaluation& ev, const std::vector<std::string>& names) {
  const auto stats = [](const ErrorStats& e) {
    return nlohmann::json{{"rmse", e.rmse}, {"mean", e.mean}, {"median", e.median}, {"max", e.max}, {"count", e.count}};
  };
  nlohmann::json sessions = nlohmann::json::array();
  for (std::size_t i = 0; i < ev.sessions.size(); ++i) {
    const SessionErrors& s = ev.sessions[i];
    nlohmann::json j{{"session", i}, {"ground_truth", i < names.size() ? names[i] : ""}, {"keyframes", s.keyframes},
                     {"linked", s.linked}};
    if (s.linked) {
      j["aligned_m"] = stats(s.aligned);
      j["map_frame_m"] = stats(s.unaligned);
    }
    sessions.push_back(j);
  }
  return {{"alignment", "se3, one for all linked keyframes"},
          {"sessions", sessions},
          {"all_aligned_m", stats(ev.all_aligned)},
          {"cross_session_loops", {{"true", ev.true_cross_session_loops}, {"false", ev.false_cross_session_loops}}}};
}

}  // namespace saloam
