#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/sim/trajectories.hpp"

namespace saloam {
namespace {

double path_length(const std::vector<Pose>& poses) {
  double len = 0;
  for (std::size_t i = 1; i < poses.size(); ++i) len += (poses[i].translation() - poses[i - 1].translation()).norm();
  return len;
}

Eigen::Vector2d heading(const Pose& p) { return p.linear().col(0).head<2>().normalized(); }

TEST(Presets, UrbanLoopIsAboutOneKilometreAtCitySpeeds) {
  const auto poses = preset_trajectory("urban-loop");
  ASSERT_GT(poses.size(), 500u);
  EXPECT_TRUE(poses.front().isApprox(Pose::Identity(), 1e-9));
  const double len = path_length(poses);
  EXPECT_GT(len, 900.0);
  EXPECT_LT(len, 1300.0);
  double v_max = 0, dv_max = 0;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    const double v = (poses[i].translation() - poses[i - 1].translation()).norm() / 0.1;
    v_max = std::max(v_max, v);
    if (i > 1) {
      const double v_prev = (poses[i - 1].translation() - poses[i - 2].translation()).norm() / 0.1;
      dv_max = std::max(dv_max, std::abs(v - v_prev) / 0.1);
    }
    // Smooth driving: at most ~6 deg of heading change per frame.
    EXPECT_LT(rotation_angle(poses[i - 1].inverse() * poses[i]), 0.1) << "frame " << i;
  }
  EXPECT_GT(v_max, 8.0);
  EXPECT_LT(v_max, 12.5);
  EXPECT_LT(dv_max, 3.0);  // m/s^2
  // The sensor's z axis stays near vertical (gentle hills only).
  for (const auto& p : poses) EXPECT_GT(p.linear()(2, 2), 0.99);
}

TEST(Presets, UrbanLoopRevisitsItsStartInTheSameDirection) {
  const auto poses = preset_trajectory("urban-loop");
  bool found = false;
  for (std::size_t i = 0; i < 200 && !found; ++i) {
    for (std::size_t j = i + 500; j < poses.size(); ++j) {
      if ((poses[i].translation() - poses[j].translation()).norm() < 2.0 && heading(poses[i]).dot(heading(poses[j])) > 0.95) {
        found = true;
        break;
      }
    }
  }
  EXPECT_TRUE(found);
}

TEST(Presets, FigureEightRevisitsInReverseDirection) {
  const auto poses = preset_trajectory("figure-eight");
  std::size_t reverse_pairs = 0;
  for (std::size_t i = 0; i < poses.size(); i += 5) {
    for (std::size_t j = i + 300; j < poses.size(); j += 5) {
      if ((poses[i].translation() - poses[j].translation()).norm() < 5.0 && heading(poses[i]).dot(heading(poses[j])) < -0.95) {
        ++reverse_pairs;
      }
    }
  }
  EXPECT_GT(reverse_pairs, 20u) << "a stretch of road must be driven again in the opposite direction";
}

TEST(Presets, AreDeterministicAndNamed) {
  for (const auto& name : preset_names()) {
    const auto a = preset_trajectory(name), b = preset_trajectory(name);
    ASSERT_EQ(a.size(), b.size()) << name;
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(a[i].isApprox(b[i], 0.0)) << name;
  }
  EXPECT_THROW(preset_trajectory("no-such-route"), ConfigError);
}

// The climbing route of issue #43: a mountain road's grades, height range,
// cross-slopes and hairpins, without crossing itself (the world has no
// bridges: two legs at different heights must stay apart).
TEST(Presets, HillClimbClimbsLikeAMountainRoad) {
  const auto poses = preset_trajectory("hill-climb");
  EXPECT_TRUE(poses.front().isApprox(Pose::Identity(), 1e-9));
  const double len = path_length(poses);
  EXPECT_GT(len, 2000.0);
  EXPECT_LT(len, 3000.0);
  double z_min = 0, z_max = 0, steepest_up = 0, steepest_down = 0, max_roll = 0, hairpin_turn = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Pose& p = poses[i];
    z_min = std::min(z_min, p.translation().z());
    z_max = std::max(z_max, p.translation().z());
    // Grade from the pose's forward axis; roll from its left axis.
    const Eigen::Vector3d fwd = p.linear().col(0), left = p.linear().col(1);
    const double grade = fwd.z() / fwd.head<2>().norm();
    steepest_up = std::max(steepest_up, grade);
    steepest_down = std::min(steepest_down, grade);
    max_roll = std::max(max_roll, std::abs(left.z()));
    if (i > 0) {
      EXPECT_LT(rotation_angle(poses[i - 1].inverse() * p), 0.1) << "frame " << i;
    }
    // Heading change over the next 150 frames: a hairpin turns through ~150 degrees.
    if (i + 150 < poses.size()) {
      hairpin_turn = std::max(hairpin_turn, std::acos(std::clamp(heading(p).dot(heading(poses[i + 150])), -1.0, 1.0)));
    }
  }
  EXPECT_GT(z_max - z_min, 150.0);
  EXPECT_LT(z_max - z_min, 250.0);
  EXPECT_GT(steepest_up, 0.14);
  EXPECT_LT(steepest_up, 0.16);
  EXPECT_LT(steepest_down, -0.13);
  EXPECT_GT(steepest_down, -0.16);
  EXPECT_GT(max_roll, 0.05);  // banked curves
  EXPECT_LT(max_roll, 0.08);
  EXPECT_GT(hairpin_turn, 2.4);
  // Stretches more than 150 m apart along the road stay 20 m apart across it.
  std::vector<double> s(poses.size(), 0.0);
  for (std::size_t i = 1; i < poses.size(); ++i) s[i] = s[i - 1] + (poses[i].translation() - poses[i - 1].translation()).norm();
  double closest = 1e9;
  for (std::size_t i = 0; i < poses.size(); i += 3) {
    for (std::size_t j = i + 1; j < poses.size(); j += 3) {
      if (s[j] - s[i] < 150.0) continue;
      closest = std::min(closest, (poses[i].translation() - poses[j].translation()).head<2>().norm());
    }
  }
  EXPECT_GT(closest, 20.0);
}

}  // namespace
}  // namespace saloam
