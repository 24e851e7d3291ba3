// Per-session accuracy of a saved map (runs/session_eval.hpp): a map made
// by hand from known truths, so every error is known exactly; and the
// truth of a simulated pass read from its sequence folder.

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/runs/session_eval.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

Pose pose_xy_yaw(double x, double y, double yaw) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(x, y, 0);
  return p;
}

// Two sessions along x (session 1 starts 40 m on, in a world where session
// 0's first pose is not the origin); truth per source frame.
struct TwoSessions {
  std::vector<std::vector<Pose>> truth;
  SavedMap map;
};

TwoSessions two_sessions() {
  TwoSessions t;
  const Pose world_from_start = pose_xy_yaw(100, -50, 0.3);
  t.truth.resize(2);
  for (int i = 0; i < 20; ++i) t.truth[0].push_back(world_from_start * pose_xy_yaw(2.0 * i, 0.1 * i, 0.01 * i));
  for (int i = 0; i < 20; ++i) t.truth[1].push_back(world_from_start * pose_xy_yaw(40 + 2.0 * i, 3.0, 0.02 * i));
  // Session 1 keyframes are source frames 5, 7, ... (first_frame 5).
  t.map.manifest.sessions = {MapSession{"a", 0, 10, true}, MapSession{"b", 5, 5, true}};
  const Pose map_from_world = t.truth[0][0].inverse();
  for (std::uint64_t f = 0; f < 10; ++f) t.map.keyframes.push_back({f * 2, 0, 0, map_from_world * t.truth[0][f * 2], {}, 0});
  for (std::uint64_t f = 0; f < 5; ++f) t.map.keyframes.push_back({f * 2, 0, 0, map_from_world * t.truth[1][5 + f * 2], {}, 1});
  return t;
}

TEST(SessionEval, ExactMapHasNoErrorAndItsCrossSessionLoopsAreTrue) {
  TwoSessions t = two_sessions();
  const Pose& a = t.map.keyframes[3].pose;
  const Pose& b = t.map.keyframes[12].pose;
  t.map.edges.push_back({3, 12, a.inverse() * b, Matrix6d::Identity(), EdgeKind::kLoop});
  t.map.edges.push_back({3, 4, a.inverse() * t.map.keyframes[4].pose, Matrix6d::Identity(), EdgeKind::kLoop});  // within a session
  const SessionEvaluation ev = evaluate_sessions(t.map, t.truth);
  ASSERT_EQ(ev.sessions.size(), 2u);
  for (const SessionErrors& s : ev.sessions) {
    EXPECT_LT(s.aligned.rmse, 1e-9);
    EXPECT_LT(s.unaligned.max, 1e-9);
  }
  EXPECT_EQ(ev.sessions[1].aligned.count, 5u);
  EXPECT_EQ(ev.true_cross_session_loops, 1u);
  EXPECT_EQ(ev.false_cross_session_loops, 0u);
}

TEST(SessionEval, ErrorsArePerSessionAfterOneAlignment) {
  TwoSessions t = two_sessions();
  // Session 1 is 1 m off along y in the map; session 0 exact. One alignment
  // over 15 keyframes moves everything by a third of a metre; the map frame
  // keeps the 1 m.
  for (MapKeyframe& kf : t.map.keyframes)
    if (kf.session == 1) kf.pose.translation().y() += 1.0;
  const Pose& a = t.map.keyframes[3].pose;
  t.map.edges.push_back({3, 12, a.inverse() * t.map.keyframes[12].pose, Matrix6d::Identity(), EdgeKind::kLoop});
  const SessionEvaluation ev = evaluate_sessions(t.map, t.truth);
  EXPECT_NEAR(ev.sessions[1].unaligned.rmse, 1.0, 1e-9);
  EXPECT_NEAR(ev.sessions[0].unaligned.rmse, 0.0, 1e-9);
  EXPECT_GT(ev.sessions[0].aligned.rmse, 0.05);
  EXPECT_LT(ev.sessions[1].aligned.rmse, 0.9);
  EXPECT_EQ(ev.false_cross_session_loops, 1u);  // the edge says 1 m the truth does not
}

TEST(SessionEval, UnlinkedSessionIsLeftOutAndMissingTruthIsAnError) {
  TwoSessions t = two_sessions();
  t.map.manifest.sessions[1].linked = false;
  for (MapKeyframe& kf : t.map.keyframes)
    if (kf.session == 1) kf.pose.translation().x() += 500;  // its own frame
  const SessionEvaluation ev = evaluate_sessions(t.map, t.truth);
  EXPECT_FALSE(ev.sessions[1].linked);
  EXPECT_LT(ev.all_aligned.rmse, 1e-9);
  EXPECT_EQ(ev.all_aligned.count, 10u);
  t.truth.pop_back();
  EXPECT_THROW(evaluate_sessions(t.map, t.truth), std::invalid_argument);
  t = two_sessions();
  t.truth[1].resize(10);  // session 1's last keyframe is source frame 13
  EXPECT_THROW(evaluate_sessions(t.map, t.truth), std::invalid_argument);
}

TEST(SessionEval, SimulatedPassTruthIsPutAtItsOrigin) {
  const testing::TempDir dir("saloam_session_eval");
  // Camera poses rebased on the first; Tr turns LiDAR x into camera z.
  std::vector<Pose> camera{Pose::Identity(), pose_xy_yaw(0, 0, 0)};
  camera[1].translation() = Eigen::Vector3d(0, 0, 2);  // 2 m forward in the camera frame
  write_kitti_poses(dir / "poses.txt", camera);
  std::ofstream(dir / "calib.txt") << "Tr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n";
  std::ofstream(dir / "simulation.yaml") << "passes: 0:10,5:15\norigin: 1 0 0 10 0 1 0 20 0 0 1 0\n";
  const std::vector<Pose> truth = read_sequence_truth(dir.path());
  ASSERT_EQ(truth.size(), 2u);
  EXPECT_LT((truth[0].translation() - Eigen::Vector3d(10, 20, 0)).norm(), 1e-9);
  EXPECT_LT((truth[1].translation() - Eigen::Vector3d(12, 20, 0)).norm(), 1e-9);
  std::filesystem::remove(dir / "poses.txt");
  EXPECT_THROW(read_sequence_truth(dir.path()), InputError);
}

}  // namespace
}  // namespace saloam
