// End-to-end: the whole SLAM system on a short simulated loop (16 beams,
// the urban-loop route every second frame: ~550 frames that drive the first
// ~200 m again at the end). The loop must close with a lower absolute error
// than the odometry alone and without any false loop.

#include <fstream>

#include <gtest/gtest.h>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/io/sequence_source.hpp"
#include "saloam/runs/odometry_run.hpp"
#include "saloam/runs/slam_run.hpp"
#include "saloam/sim/simulator.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

TEST(SlamEndToEnd, ShortLoopClosesWithLowerErrorAndNoFalseLoop) {
  testing::TempDir dir("saloam_slam_e2e");
  SimulationOptions sim;
  sim.preset = "urban-loop";
  sim.stride = 2;
  sim.beams = 16;
  sim.seed = 3;
  sim.labels = LabelMode::kNoisy;
  sim.show_progress = false;
  const auto simulated = simulate_sequence(sim, dir / "sequence");
  ASSERT_GT(simulated.frames, 300u);

  SequenceFolderSource source{SequenceReader(dir / "sequence")};
  SaloamConfig config;  // the defaults: Scan Context detector, normalized acceptance
  SlamRunOptions options;
  options.show_progress = false;
  options.write_map = false;
  const SlamRunResult result = run_slam(source, config, std::nullopt, dir / "out", options);

  ASSERT_EQ(result.frames, source.size());
  ASSERT_TRUE(result.odometry_evaluation && result.slam_evaluation && result.loop_summary);
  const LoopSummary& loops = *result.loop_summary;
  const double ate_odometry = result.odometry_evaluation->ate.aligned.rmse;
  const double ate_slam = result.slam_evaluation->ate.aligned.rmse;
  std::printf("ATE odometry %.3f m, loop closed %.3f m; loops %zu accepted (%zu true, %zu false), %zu verified\n",
              ate_odometry, ate_slam, loops.accepted, loops.accepted_true, loops.accepted_false, loops.verified);
  EXPECT_GE(loops.accepted_true, 1u);
  EXPECT_EQ(loops.accepted_false, 0u);
  EXPECT_EQ(loops.missed_stretches, 0u);
  EXPECT_LT(ate_slam, 0.8 * ate_odometry);

  // Every output exists; poses.txt has one pose per frame.
  for (const char* file : {"poses.txt", "poses_tum.txt", "poses_odometry.txt", "poses_odometry_tum.txt", "loops.csv",
                           "timing.json", "trajectories.png", "eval_slam.json", "eval_odometry.json", "summary.json"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / file)) << file;
  }
  std::ifstream poses(dir / "out" / "poses.txt");
  std::size_t lines = 0;
  for (std::string line; std::getline(poses, line);) ++lines;
  EXPECT_EQ(lines, source.size());
}

}  // namespace
}  // namespace saloam

namespace saloam {
namespace {

// The SLAM's output does not depend on how many threads the odometry uses.
TEST(SlamEndToEnd, OutputIndependentOfThreadCount) {
  testing::TempDir dir("saloam_slam_threads");
  SimulationOptions sim;
  sim.preset = "urban-loop";
  sim.end_frame = 60;
  sim.beams = 16;
  sim.seed = 4;
  sim.labels = LabelMode::kNoisy;
  sim.show_progress = false;
  simulate_sequence(sim, dir.path());
  const SequenceReader reader(dir.path());
  auto run = [&](int threads) {
    SaloamConfig config;
    config.odometry.threads = threads;
    SlamSystem slam(config, std::nullopt);
    for (std::size_t i = 0; i < reader.size(); ++i) slam.process(reader.load_scan(i), reader.times()[i]);
    return slam.optimized_poses();
  };
  const std::vector<Pose> one = run(1), two = run(2);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_TRUE(one[i].matrix() == two[i].matrix()) << "frame " << i;
  }
}

}  // namespace
}  // namespace saloam


namespace saloam {
namespace {

// A run never writes into the sequence folder: its poses.txt is the ground truth.
TEST(SlamEndToEnd, RefusesToWriteOverTheSequence) {
  testing::TempDir dir("saloam_slam_out");
  SimulationOptions sim;
  sim.preset = "straight";
  sim.end_frame = 3;
  sim.beams = 16;
  sim.show_progress = false;
  simulate_sequence(sim, dir.path());
  const auto before = std::filesystem::file_size(dir / "poses.txt");
  SequenceFolderSource source{SequenceReader(dir.path())};
  SlamRunOptions options;
  options.show_progress = false;
  const std::string slam_error = testing::input_error_of(
      [&] { run_slam(source, SaloamConfig{}, std::nullopt, dir.path() / ".", options); });
  EXPECT_NE(slam_error.find("is the sequence folder"), std::string::npos) << slam_error;
  OdometryRunOptions odometry_options;
  odometry_options.show_progress = false;
  const std::string odometry_error =
      testing::input_error_of([&] { run_odometry(source, OdometryConfig{}, dir.path(), odometry_options); });
  EXPECT_NE(odometry_error.find("overwrite its ground truth"), std::string::npos) << odometry_error;
  // A link to the sequence reached through a folder not yet made and `..`:
  // the folder the system would write into is the sequence's.
  testing::TempDir elsewhere("saloam_slam_link");
  std::filesystem::create_directory_symlink(dir.path(), elsewhere / "link");
  const std::string link_error = testing::input_error_of(
      [&] { run_slam(source, SaloamConfig{}, std::nullopt, elsewhere / "new" / ".." / "link", options); });
  EXPECT_NE(link_error.find("is the sequence folder"), std::string::npos) << link_error;
  EXPECT_EQ(std::filesystem::file_size(dir / "poses.txt"), before);
}

}  // namespace
}  // namespace saloam
