// The odometry's output does not depend on the thread count, in every mode:
// {serial, parallel} x {semantic, label-agnostic} x {de-skew on, off}. The
// parallel association writes per feature and the normal equations are
// summed in blocks fixed by the number of residuals (registration.hpp), so
// the poses are bit-identical, not merely close.

#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "saloam/io/sequence.hpp"
#include "saloam/odometry/semantic_odometry.hpp"
#include "saloam/sim/simulator.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

/// 25 frames of the urban loop at 32 beams with the network-like noisy labels, simulated once.
const std::filesystem::path& sequence() {
  static const testing::TempDir dir("saloam_odometry_threads");
  static const bool simulated = [] {
    SimulationOptions sim;
    sim.preset = "urban-loop";
    sim.end_frame = 25;
    sim.beams = 32;
    sim.seed = 6;
    sim.labels = LabelMode::kNoisy;
    sim.show_progress = false;
    simulate_sequence(sim, dir.path());
    return true;
  }();
  (void)simulated;
  return dir.path();
}

std::vector<Pose> odometry_poses(bool semantics, bool deskew, int threads) {
  OdometryConfig config;
  config.use_semantics = semantics;
  config.deskew = deskew;
  config.threads = threads;
  SequenceOptions options;
  options.ignore_labels = !semantics;
  const SequenceReader reader(sequence(), options);
  SemanticOdometry odometry(config);
  for (std::size_t i = 0; i < reader.size(); ++i) odometry.register_frame(reader.load_scan(i), reader.times()[i]);
  return odometry.poses();
}

class OdometryThreads : public ::testing::TestWithParam<std::tuple<bool, bool>> {};

TEST_P(OdometryThreads, PosesAreBitIdenticalSerialAndParallel) {
  const auto [semantics, deskew] = GetParam();
  const std::vector<Pose> serial = odometry_poses(semantics, deskew, 1);
  const std::vector<Pose> parallel = odometry_poses(semantics, deskew, 2);
  ASSERT_EQ(serial.size(), 25u);
  ASSERT_EQ(parallel.size(), serial.size());
  EXPECT_GT(serial.back().translation().norm(), 5.0) << "the car drives";
  for (std::size_t i = 0; i < serial.size(); ++i) {
    EXPECT_TRUE(serial[i].matrix() == parallel[i].matrix()) << "frame " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(EveryMode, OdometryThreads, ::testing::Combine(::testing::Bool(), ::testing::Bool()),
                         [](const ::testing::TestParamInfo<std::tuple<bool, bool>>& info) {
                           return std::string(std::get<0>(info.param) ? "Semantic" : "LabelAgnostic") +
                                  (std::get<1>(info.param) ? "Deskewed" : "Skewed");
                         });

}  // namespace
}  // namespace saloam
