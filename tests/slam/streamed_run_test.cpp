// A run fed by the simulator in memory (SimulatedSource, as the demo does)
// must give what the same run gives over the written sequence folder, and
// the sequence it keeps must be the one `saloam simulate` writes.

#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "saloam/io/ply.hpp"
#include "saloam/io/sequence_source.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/runs/map_building.hpp"
#include "saloam/runs/slam_run.hpp"
#include "saloam/sim/simulated_source.hpp"
#include "saloam/sim/simulator.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

SimulationOptions short_route() {
  SimulationOptions sim;
  sim.preset = "urban-loop";
  sim.end_frame = 40;
  sim.beams = 16;
  sim.seed = 5;
  sim.labels = LabelMode::kNoisy;
  sim.show_progress = false;
  return sim;
}

std::string contents(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  EXPECT_TRUE(in) << file;
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

SlamRunOptions quiet_run() {
  SlamRunOptions options;
  options.show_progress = false;
  return options;
}

TEST(StreamedRun, GivesTheRunOverTheWrittenSequenceAndKeepsTheSameSequence) {
  testing::TempDir dir("saloam_streamed_run");
  const SimulationOptions sim = short_route();
  simulate_sequence(sim, dir / "written");
  SequenceFolderSource folder{SequenceReader(dir / "written")};
  const SaloamConfig config;
  const SlamRunResult from_folder = run_slam(folder, config, std::nullopt, dir / "out_folder", quiet_run());

  const SimulatedSequence sequence(sim);
  SlamRunResult streamed;
  {
    SimulatedSource source(sequence, 4, dir / "kept");
    streamed = run_slam(source, config, std::nullopt, dir / "out_stream", quiet_run());
  }

  // The same trajectories and loops. (The folder's Tr and poses went through
  // text files, so the numbers agree to the printed precision, not bit for bit.)
  ASSERT_EQ(streamed.frames, from_folder.frames);
  for (const char* file : {"poses.txt", "poses_odometry.txt"}) {
    const auto a = read_kitti_poses(dir / "out_stream" / file), b = read_kitti_poses(dir / "out_folder" / file);
    ASSERT_EQ(a.size(), b.size()) << file;
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_LT((a[i].matrix() - b[i].matrix()).cwiseAbs().maxCoeff(), 1e-7) << file << " pose " << i;
    }
  }
  EXPECT_EQ(streamed.loops_verified, from_folder.loops_verified);
  EXPECT_EQ(streamed.loops_accepted, from_folder.loops_accepted);
  ASSERT_TRUE(streamed.slam_evaluation && from_folder.slam_evaluation);
  EXPECT_NEAR(streamed.slam_evaluation->ate.aligned.rmse, from_folder.slam_evaluation->ate.aligned.rmse, 1e-6);

  // The map of a stream comes from the downsampled copies it kept: the same
  // map up to the second voxelisation (which merges about a tenth of the voxels).
  const auto map_folder = read_ply(dir / "out_folder" / "map.ply");
  const auto map_stream = read_ply(dir / "out_stream" / "map.ply");
  ASSERT_GT(map_folder.size(), 1000u);
  EXPECT_NEAR(static_cast<double>(map_stream.size()), static_cast<double>(map_folder.size()),
              0.15 * static_cast<double>(map_folder.size()));

  // --keep-sequence writes exactly what `saloam simulate` writes.
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir / "written")) {
    if (!entry.is_regular_file() || entry.path().filename() == OutputFolder::kRecordName) continue;  // per run
    const auto relative = std::filesystem::relative(entry.path(), dir / "written");
    ASSERT_TRUE(std::filesystem::exists(dir / "kept" / relative)) << relative;
    EXPECT_EQ(contents(dir / "kept" / relative), contents(entry.path())) << relative;
  }
}

TEST(StreamedRun, ServesFramesOnceInOrderAndStopsWhenDestroyedEarly) {
  testing::TempDir dir("saloam_stream_order");
  const SimulatedSequence sequence(short_route());
  {
    SimulatedSource source(sequence, 2, dir / "kept");
    EXPECT_FALSE(source.info().rereadable);
    EXPECT_THROW((void)source.scan(1), std::logic_error);  // frame 0 comes first
    EXPECT_GT(source.scan(0).size(), 1000u);
    EXPECT_GT(source.scan(1).size(), 1000u);
    EXPECT_THROW((void)source.scan(1), std::logic_error);  // once only
    const double miou = source.label_score().miou();
    EXPECT_GT(miou, 0.3);
    EXPECT_LT(miou, 0.9);
  }  // destroyed with frames still to come: the worker stops, the kept folder is trimmed
  const SequenceReader kept(dir / "kept");
  EXPECT_GE(kept.size(), 2u);
  EXPECT_LT(kept.size(), sequence.size());
  EXPECT_EQ(kept.camera_poses().size(), kept.size());
  EXPECT_EQ(kept.times().size(), kept.size());
}

TEST(MapScanStore, KeepsOnlyEveryStepthScanAndBuildsTheMapOfTheScans) {
  testing::TempDir dir("saloam_map_store");
  const SimulationOptions sim = short_route();
  simulate_sequence(sim, dir.path());
  const SequenceReader reader(dir.path());
  SequenceFolderSource source{SequenceReader(dir.path())};
  SemanticMapOptions options;
  options.voxel_size = 0.25;
  const std::vector<Pose> poses = reader.lidar_poses();

  MapScanStore store(options, 3);
  for (std::size_t k = 0; k < reader.size(); ++k) store.offer(k, reader.load_scan(k));
  const LabelledCloud direct = build_semantic_map(source, poses, options, 3, false);
  const LabelledCloud stored = store.build(poses, false);
  ASSERT_GT(direct.size(), 1000u);
  EXPECT_NEAR(static_cast<double>(stored.size()), static_cast<double>(direct.size()),
              0.15 * static_cast<double>(direct.size()));
  // About 14 of 40 scans, each a fraction of its points.
  EXPECT_GT(store.bytes(), 0u);
  EXPECT_LT(store.bytes(), 14 * reader.load_scan(0).size() * 20);
}

}  // namespace
}  // namespace saloam
