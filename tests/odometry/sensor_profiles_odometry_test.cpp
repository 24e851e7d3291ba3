// Every shipped sensor profile end to end: the simulator renders a short
// drive with the profile's lasers, mount and noise; the odometry, set up with
// the same profile (apply_sensor_profile, as `--sensor` does), follows it.
// The scans arrive as a driver publishes them (ring field, per-point times);
// the VLP-16 also without them, stored laser after laser as a .bin file
// keeps it, and in no order at all, where the profile's laser elevations
// sort the points into rings.

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "saloam/core/lie.hpp"
#include "saloam/core/sensor_profile.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/odometry/semantic_odometry.hpp"
#include "saloam/sim/simulator.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

const std::vector<SensorProfile>& shipped() {
  static const auto all = load_sensor_profiles(testing::source_dir() / "config" / "sensors");
  return all;
}

const SensorProfile& named(const std::string& name) {
  const auto it = std::find_if(shipped().begin(), shipped().end(), [&](const auto& p) { return p.name == name; });
  if (it == shipped().end()) throw std::runtime_error("no profile " + name);
  return *it;
}

enum class Delivery { kDriver, kStorageOrder, kShuffled };

LabelledCloud delivered(LabelledCloud cloud, Delivery delivery, std::uint32_t seed) {
  if (delivery == Delivery::kDriver) return cloud;
  cloud.ring.clear();
  cloud.time.clear();
  if (delivery == Delivery::kStorageOrder) return cloud;
  std::vector<std::size_t> order(cloud.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin(), order.end(), std::mt19937(seed));
  LabelledCloud shuffled;
  shuffled.has_labels = cloud.has_labels;
  for (const std::size_t i : order) shuffled.push_back_from(cloud, i);
  return shuffled;
}

struct Errors {
  double worst_step = 0;  ///< [m] largest error of one frame's relative motion
  double drift = 0;       ///< end-point error over the path length
};

/// The urban loop's frames 0:frames in world `seed`, rendered with `profile`.
SimulationOptions drive_options(const SensorProfile& profile, std::size_t frames, std::uint64_t seed) {
  SimulationOptions options;
  options.preset = "urban-loop";
  options.end_frame = frames;
  options.seed = seed;
  options.sensor = profile;
  options.azimuth_steps = profile.simulation.azimuth_steps;
  options.show_progress = false;
  return options;
}

struct Followed {
  std::vector<Pose> truth;     ///< LiDAR poses of the drive
  std::vector<Pose> estimate;  ///< the odometry's
};

/// The drive of `options` registered by the odometry set up with the same
/// profile (and `level_line_max_rise`, `use_semantics`), its scans delivered
/// as `delivery` says.
Followed follow_drive(const SimulationOptions& options, double level_line_max_rise, Delivery delivery,
                      bool use_semantics = true) {
  const SimulatedSequence sequence(options);
  OdometryConfig config;
  apply_sensor_profile(*options.sensor, config.features);
  config.level_line_max_rise = level_line_max_rise;
  config.use_semantics = use_semantics;
  SemanticOdometry odometry(config);
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    odometry.register_frame(delivered(sequence.render(i).cloud, delivery, static_cast<std::uint32_t>(i)),
                            sequence.times()[i]);
  }
  return {camera_to_lidar_poses(sequence.camera_poses(), sequence.velo_to_cam()), odometry.poses()};
}

/// The drive's frames 0:frames with `profile`, registered by the odometry
/// set up with the same profile.
Errors follow(const SensorProfile& profile, Delivery delivery, std::size_t frames) {
  const auto [truth, estimate] = follow_drive(drive_options(profile, frames, 7), 0.0, delivery);
  Errors e;
  double path = 0;
  for (std::size_t i = 1; i < truth.size(); ++i) {
    const Pose step = truth[i - 1].inverse() * truth[i];
    const Pose estimated = estimate[i - 1].inverse() * estimate[i];
    e.worst_step = std::max(e.worst_step, (step.inverse() * estimated).translation().norm());
    path += step.translation().norm();
  }
  e.drift = (truth.back().translation() - estimate.back().translation()).norm() / path;
  std::printf("%s, delivery %d: worst step %.3f m, drift %.2f %% over %.1f m\n", profile.name.c_str(),
              static_cast<int>(delivery), e.worst_step, 100 * e.drift, path);
  return e;
}

TEST(SensorProfilesOdometry, EveryShippedSensorFollowsAShortDrive) {
  for (const auto& profile : shipped()) {
    SCOPED_TRACE(profile.name);
    const Errors e = follow(profile, Delivery::kDriver, 12);
    EXPECT_LT(e.worst_step, 0.05);
    EXPECT_LT(e.drift, 0.01);
  }
}

TEST(SensorProfilesOdometry, Vlp16WithoutRingsOrTimes) {
  for (const Delivery delivery : {Delivery::kStorageOrder, Delivery::kShuffled}) {
    SCOPED_TRACE(static_cast<int>(delivery));
    const Errors e = follow(named("vlp16"), delivery, 12);
    EXPECT_LT(e.worst_step, 0.05);
    EXPECT_LT(e.drift, 0.01);
  }
}

/// [deg] rotation error of the drive's end relative to its start: the
/// odometry set up with the VLP-16 (1 m mount) on 120 frames of the urban
/// loop with emulated network labels (or without labels).
double vlp16_end_rotation_error_deg(double level_line_max_rise, bool use_semantics = true) {
  SimulationOptions options = drive_options(named("vlp16"), 120, 3);
  options.labels = LabelMode::kNoisy;
  const auto [truth, estimate] = follow_drive(options, level_line_max_rise, Delivery::kDriver, use_semantics);
  const Pose moved = truth.front().inverse() * truth.back();
  const Pose estimated = estimate.front().inverse() * estimate.back();
  const double error = rotation_angle(moved.inverse() * estimated) * 180.0 / M_PI;
  std::printf("vlp16, level_line_max_rise %.2f, semantics %d: end rotation error %.3f deg, end %.1f m from the start\n",
              level_line_max_rise, use_semantics, error, moved.translation().norm());
  return error;
}

// 16 two-degree rings: an edge feature's map neighbours often come from one
// ring seen by several frames, whose footprint's height moves with the
// sensor; fitted as a line, it pulls the pitch. Level lines constrain only
// horizontally (odometry.level_line_max_rise). Measured here: 0.10 deg at
// the end, 0.93 deg with level lines matched as lines.
TEST(SensorProfilesOdometry, Vlp16LevelLinesDoNotTiltThePose) {
  const double fixed = vlp16_end_rotation_error_deg(0.5);
  EXPECT_LT(fixed, 0.25);
  const double as_lines = vlp16_end_rotation_error_deg(0.0);
  EXPECT_GT(as_lines, 2 * fixed);  // the route shows the problem
}

// The same without labels, where the ground's edges add level lines of
// their own. Measured here: 0.45 deg at the end, 4.17 deg with level lines
// matched as lines.
TEST(SensorProfilesOdometry, Vlp16LevelLinesDoNotTiltThePoseWithoutLabels) {
  const double fixed = vlp16_end_rotation_error_deg(0.5, false);
  EXPECT_LT(fixed, 0.9);
  const double as_lines = vlp16_end_rotation_error_deg(0.0, false);
  EXPECT_GT(as_lines, 4 * fixed);
}

}  // namespace
}  // namespace saloam
