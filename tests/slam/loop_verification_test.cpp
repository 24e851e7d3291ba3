// Geometric verification on simulated scans of the urban-loop world: a true
// revisit is accepted from a drifted guess (and from the descriptor's yaw
// when revisited in reverse), two different places are rejected.

#include <gtest/gtest.h>

#include "saloam/core/lie.hpp"
#include "saloam/odometry/features.hpp"
#include "saloam/odometry/local_map.hpp"
#include "saloam/sim/lidar.hpp"
#include "saloam/sim/trajectories.hpp"
#include "saloam/sim/world.hpp"
#include "saloam/slam/loop_verification.hpp"

namespace saloam {
namespace {

const std::vector<Pose>& route() {
  static const std::vector<Pose> poses = preset_trajectory("urban-loop");
  return poses;
}

const World& world() {
  static const World w = build_world(route(), 11);
  return w;
}

// Odometry-style features (classes grouped, downsampled) of a still scan at `pose`.
ScanFeatures features_at(const Pose& pose) {
  SweepSpec sweep;
  sweep.start = sweep.end = pose;
  sweep.skew = false;
  sweep.seed = 3;
  const SimulatedScan scan = simulate_scan(world(), LidarModel::hdl64e(64), sweep);
  const SaloamConfig config;
  ScanFeatures f = extract_features(scan.cloud, config.odometry.features, true);
  for (auto& c : f.edges.classes) c = class_group(c);
  for (auto& c : f.planars.classes) c = class_group(c);
  const ClassVoxelSizes voxels = class_voxel_sizes(config.odometry);
  f.edges = voxel_downsample(f.edges, voxels);
  f.planars = voxel_downsample(f.planars, voxels);
  return f;
}

// Submap of the keyframes around route frame `center`, in that frame's coordinates.
LoopSubmap submap_around(std::size_t center, const LoopVerificationSettings& settings) {
  LoopSubmap submap(settings);
  for (int k = -3; k <= 3; ++k) {
    const std::size_t i = center + static_cast<std::size_t>(k * 10);
    submap.add(features_at(route()[i]), route()[center].inverse() * route()[i]);
  }
  return submap;
}

Pose yaw_pose(double x, double y, double yaw) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0);
  return T;
}

class LoopVerificationTest : public ::testing::Test {
 protected:
  LoopVerificationSettings settings = LoopVerificationSettings::from_config(SaloamConfig{});
  static constexpr std::size_t kCenter = 300;
};

TEST_F(LoopVerificationTest, AcceptsATrueRevisitFromADriftedGuess) {
  const LoopSubmap submap = submap_around(kCenter, settings);
  // The revisit: 1.2 m to the side and 2 m further, turned by 4 degrees.
  const Pose truth = yaw_pose(2.0, 1.2, 4.0 * M_PI / 180);
  const ScanFeatures query = features_at(route()[kCenter] * truth);
  // Odometry drift put the guess 2.5 m and 3 degrees off.
  const std::vector<Pose> guesses{truth * yaw_pose(-1.5, 2.0, -3.0 * M_PI / 180)};
  const LoopVerification v = verify_loop(query, submap, guesses, settings);
  EXPECT_TRUE(v.accepted) << v.reason;
  EXPECT_TRUE(v.passes_normalized_test);
  const Pose error = truth.inverse() * v.relative;
  EXPECT_LT(error.translation().norm(), 0.1);
  EXPECT_LT(rotation_angle(error) * 180 / M_PI, 0.3);
  EXPECT_GT(v.inlier_fraction, 0.6);
  EXPECT_LT(v.mean_residual, 0.05);
}

TEST_F(LoopVerificationTest, AcceptsAReverseRevisitFromTheDescriptorYaw) {
  const LoopSubmap submap = submap_around(kCenter, settings);
  // Driving the other way in the other lane.
  const Pose truth = yaw_pose(1.0, 3.2, M_PI);
  const ScanFeatures query = features_at(route()[kCenter] * truth);
  // The drifted estimate is 20 degrees off, far outside ICP's basin; Scan
  // Context's column shift gives the heading to 6 degrees (one sector),
  // without any translation.
  const std::vector<Pose> guesses{truth * yaw_pose(0, 0, 20 * M_PI / 180), yaw_pose(0, 0, M_PI + 5 * M_PI / 180)};
  const LoopVerification v = verify_loop(query, submap, guesses, settings);
  EXPECT_TRUE(v.accepted) << v.reason;
  EXPECT_EQ(v.guess, 1u);
  const Pose error = truth.inverse() * v.relative;
  EXPECT_LT(error.translation().norm(), 0.15);
  EXPECT_LT(rotation_angle(error) * 180 / M_PI, 0.5);
}

TEST_F(LoopVerificationTest, RejectsTwoDifferentPlaces) {
  const LoopSubmap submap = submap_around(kCenter, settings);
  // A scan 250 m further along the route, presented as if it were here.
  const ScanFeatures elsewhere = features_at(route()[kCenter + 250]);
  const std::vector<Pose> guesses{Pose::Identity(), yaw_pose(0, 0, 0.5)};
  const LoopVerification v = verify_loop(elsewhere, submap, guesses, settings);
  EXPECT_FALSE(v.accepted) << "inliers " << v.inlier_fraction << " residual " << v.mean_residual;
  EXPECT_FALSE(v.reason.empty());
}

}  // namespace
}  // namespace saloam
