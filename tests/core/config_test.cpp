#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "saloam/core/config.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

TEST(Config, TableOneDefaults) {
  const SaloamConfig c;
  EXPECT_DOUBLE_EQ(c.odometry.features.alpha, 0.1);
  EXPECT_EQ(c.odometry.features.num_sectors, 6);
  EXPECT_EQ(c.odometry.features.edges_per_sector, 20);
  EXPECT_EQ(c.odometry.features.planars_per_sector, 50);
  EXPECT_EQ(c.odometry.local_map_frames, 20);
  EXPECT_EQ(c.odometry.edge_neighbours, 5);
  EXPECT_EQ(c.odometry.planar_neighbours, 5);
  EXPECT_DOUBLE_EQ(c.odometry.plane_normal_tolerance, 0.05);
  EXPECT_DOUBLE_EQ(c.loop.delta_min, 15.0);
  EXPECT_DOUBLE_EQ(c.loop.delta_max, 100.0);
  EXPECT_EQ(c.loop.num_candidates, 64);
  EXPECT_DOUBLE_EQ(c.loop.zeta, 0.95);
  EXPECT_EQ(c.loop.num_loop, 5);
  EXPECT_DOUBLE_EQ(c.loop.delta_r, 100.0);
  EXPECT_DOUBLE_EQ(c.loop.sigma, 0.05);  // Table I's sigma: the drift rate of Eq. 3
}

TEST(Config, YamlRoundTripIsIdentity) {
  SaloamConfig c;
  apply_config_override(c, "odometry.features.alpha=0.25");
  apply_config_override(c, "odometry.class_weight.pole=3");
  apply_config_override(c, "loop.sgpr_model=/tmp/x.sgw");
  const std::string yaml = config_to_yaml(c);
  SaloamConfig back;
  apply_config_yaml(back, yaml, "roundtrip");
  EXPECT_EQ(config_to_yaml(back), yaml);
  EXPECT_DOUBLE_EQ(back.odometry.features.alpha, 0.25);
  EXPECT_DOUBLE_EQ(back.odometry.class_weight.at("pole"), 3.0);
  EXPECT_EQ(back.loop.sgpr_model, "/tmp/x.sgw");
}

// The shipped config/saloam.yaml documents every key with its default.
TEST(Config, ShippedFileHoldsTheDefaults) {
  const auto loaded = load_config(testing::source_dir() / "config" / "saloam.yaml");
  EXPECT_EQ(config_to_yaml(loaded), config_to_yaml(SaloamConfig{}))
      << "regenerate it with: build/saloam config > config/saloam.yaml";
}

// config/real_kitti.yaml changes only the pose instant (real KITTI: mid-sweep).
TEST(Config, ShippedRealKittiFileSetsMidSweepPoses) {
  const auto loaded = load_config(testing::source_dir() / "config" / "real_kitti.yaml");
  EXPECT_DOUBLE_EQ(loaded.odometry.features.pose_time_in_sweep, 0.05);
  SaloamConfig expected;
  expected.odometry.features.pose_time_in_sweep = 0.05;
  EXPECT_EQ(config_to_yaml(loaded), config_to_yaml(expected));
}

TEST(Config, InfinityRoundTrips) {
  SaloamConfig c;
  apply_config_override(c, "odometry.features.ground_edge_alpha=.inf");
  EXPECT_TRUE(std::isinf(c.odometry.features.ground_edge_alpha));
  testing::TempDir dir;
  const auto file = dir.path() / "inf.yaml";
  std::ofstream(file) << config_to_yaml(c);
  EXPECT_TRUE(std::isinf(load_config(file).odometry.features.ground_edge_alpha));
}

TEST(Config, OverridesByShortAndLongName) {
  SaloamConfig c;
  apply_config_override(c, "alpha=0.3");
  EXPECT_DOUBLE_EQ(c.odometry.features.alpha, 0.3);
  apply_config_override(c, "zeta=0.9");
  EXPECT_DOUBLE_EQ(c.loop.zeta, 0.9);
  apply_config_override(c, "odometry.use_semantics=false");
  EXPECT_FALSE(c.odometry.use_semantics);
  apply_config_override(c, "odometry.class_voxel_size={road: 1.5, pole: 0.05}");
  EXPECT_DOUBLE_EQ(c.odometry.class_voxel_size.at("road"), 1.5);
  EXPECT_DOUBLE_EQ(c.odometry.class_voxel_size.at("pole"), 0.05);
  EXPECT_DOUBLE_EQ(class_value(c.odometry.class_voxel_size, cls::kRoad, 0.0), 1.5);
  EXPECT_DOUBLE_EQ(class_value(c.odometry.class_voxel_size, cls::kCar, 0.0), 0.4);  // default entry
  EXPECT_DOUBLE_EQ(class_value(c.odometry.class_weight, cls::kMovingCar, 0.0), 1.0);
}

TEST(Config, ErrorsNameTheProblem) {
  SaloamConfig c;
  auto expect_error = [&](const std::string& assignment, const std::string& fragment) {
    try {
      apply_config_override(c, assignment);
      FAIL() << "no error for " << assignment;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect_error("nonsense=1", "unknown configuration key 'nonsense'");
  expect_error("odometry.alpha_typo=1", "unknown configuration key");
  expect_error("alpha=abc", "wrong type");
  expect_error("alpha", "expected key=value");
  expect_error("odometry.class_weight.spaceship=2", "unknown class 'spaceship'");

  try {
    apply_config_yaml(c, "odometry:\n  local_map_frames: [1, 2]\n", "test.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("test.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("odometry.local_map_frames"), std::string::npos);
  }
  EXPECT_THROW(apply_config_yaml(c, "odometry: {\n", "broken.yaml"), ConfigError);
  EXPECT_THROW(load_config("/nonexistent/saloam.yaml"), InputError);
}

}  // namespace
}  // namespace saloam

