// The handheld walk (issue #51): a walker's speeds, a hand's rotation rates,
// and the simulator sampling its motion within every sweep.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/sim/handheld_walk.hpp"
#include "saloam/sim/lidar.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sim/trajectories.hpp"

namespace saloam {
namespace {

constexpr double kDeg = M_PI / 180.0;

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

TEST(HandheldWalk, WalksAStreetAtAWalkersPace) {
  const HandheldWalk walk;
  EXPECT_DOUBLE_EQ(walk.duration(), 60.0);
  double length = 0, fastest = 0;
  const double dt = 0.1;
  for (double t = dt; t <= walk.duration(); t += dt) {
    const double step = (walk.track(t).translation() - walk.track(t - dt).translation()).norm();
    length += step;
    fastest = std::max(fastest, step / dt);
  }
  EXPECT_GT(length, 60.0);
  EXPECT_LT(length, 80.0);
  EXPECT_GT(fastest, 1.2);
  EXPECT_LT(fastest, 1.7);
  // Standing still at the start; the track is level at the sensor's height.
  EXPECT_TRUE(walk.track(0.0).isApprox(Pose::Identity(), 1e-12));
  EXPECT_LT((walk.track(0.5).translation() - walk.track(0.0).translation()).norm(), 1e-6);
  for (double t = 0; t <= walk.duration(); t += 1.0) {
    EXPECT_NEAR(walk.track(t).translation().z(), 0.0, 1e-12);
    EXPECT_NEAR(walk.track(t).linear()(2, 2), 1.0, 1e-12);
  }
}

// Rotation rates like a hand's (issue #51's walk: median 45 deg/s, p95 122,
// peak 195): look-arounds up to ~190 deg/s over the gait's sway and shake.
TEST(HandheldWalk, TurnsAsFastAsAHand) {
  const HandheldWalk walk;
  std::vector<double> rates;
  const double dt = 0.005;
  double largest_look = 0, lowest_up = 1;
  for (double t = dt; t <= walk.duration(); t += dt) {
    rates.push_back(rotation_angle(walk.sensor(t - dt).inverse() * walk.sensor(t)) / dt / kDeg);
    const Eigen::Vector3d forward = walk.sensor(t).linear().col(0), along = walk.track(t).linear().col(0);
    largest_look = std::max(largest_look, std::acos(std::clamp(forward.head<2>().normalized().dot(along.head<2>()), -1.0, 1.0)));
    lowest_up = std::min(lowest_up, walk.sensor(t).linear()(2, 2));
  }
  EXPECT_GT(percentile(rates, 1.0), 170.0);
  EXPECT_LT(percentile(rates, 1.0), 215.0);
  EXPECT_GT(percentile(rates, 0.95), 60.0);
  EXPECT_GT(percentile(rates, 0.5), 5.0);
  EXPECT_GT(largest_look, 170.0 * kDeg) << "it looks behind while standing";
  // Held within ~10 deg of level (pitched a little down, swaying).
  EXPECT_GT(lowest_up, std::cos(12.0 * kDeg));
  EXPECT_LT(walk.sensor(30.0).linear()(2, 2), std::cos(1.0 * kDeg));
}

TEST(HandheldWalk, IsThePresetsMotion) {
  const auto poses = preset_trajectory("handheld-walk");
  ASSERT_EQ(poses.size(), 601u);
  const ContinuousMotion motion = preset_motion("handheld-walk");
  ASSERT_TRUE(motion);
  for (std::size_t i = 0; i < poses.size(); i += 37) EXPECT_TRUE(poses[i].isApprox(motion(0.1 * static_cast<double>(i)), 1e-12));
  EXPECT_EQ(preset_track("handheld-walk").size(), poses.size());
  EXPECT_FALSE(preset_motion("urban-loop"));
  EXPECT_EQ(preset_track("straight").size(), preset_trajectory("straight").size());
}

TEST(SweepKnots, ColumnsFollowTheKnots) {
  const LidarModel lidar = LidarModel::hdl64e(64);
  SweepSpec sweep;
  for (int j = 0; j <= 4; ++j) sweep.knots.push_back(Pose(Eigen::AngleAxisd(0.1 * j * j, Eigen::Vector3d::UnitZ())));
  sweep.start = sweep.knots.front();
  sweep.end = sweep.knots.back();
  for (int column = 0; column < lidar.azimuth_steps; column += 97) {
    const double f = 4.0 * lidar.column_fraction(column);
    const double j = std::floor(f), a = f - j;
    const double angle = 0.1 * ((1 - a) * j * j + a * (j + 1) * (j + 1));
    EXPECT_NEAR(rotation_angle(column_pose(lidar, sweep, column)), angle, 1e-9) << column;
  }
  sweep.knots.clear();  // linear from start to end
  EXPECT_NEAR(rotation_angle(column_pose(lidar, sweep, lidar.azimuth_steps / 2)), 0.8, 1e-3);
}

// The walk renders as a sequence (its world built along its track), once:
// passes of it are refused.
TEST(HandheldWalk, RendersOnceWithoutPasses) {
  SimulationOptions options;
  options.preset = "handheld-walk";
  options.first_frame = 50;
  options.end_frame = 52;
  options.show_progress = false;
  const SimulatedSequence sequence(options);
  ASSERT_EQ(sequence.size(), 2u);
  EXPECT_GT(sequence.render(0).cloud.size(), 10000u);
  options.passes = {RoutePass{0, 300, false}};
  EXPECT_THROW(SimulatedSequence{options}, ConfigError);
}

}  // namespace
}  // namespace saloam
