// The live SLAM's queries from the side (loop.lateral_query_offset) on the
// figure-eight route's frames 880:1400 (16 beams, every second frame, noisy
// labels): about 180 m of a lobe, the U-turn, and the lobe driven back in
// the opposite lane, 3.2 m beside the first drive. Scan Context compares
// scans taken from one spot: described from the sensor, the way back scores
// its own place just above the threshold, and not every search finds it;
// described from a lane width to the left, it scores it well above.

#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "saloam/runs/loop_truth.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/slam/slam_system.hpp"

namespace saloam {
namespace {

struct Drive {
  std::vector<LabelledCloud> scans;
  std::vector<double> times;
  std::vector<Pose> truth;  ///< T_first<-sensor per frame (LiDAR frame)
};

const Drive& figure_eight_end() {
  static const Drive drive = [] {
    SimulationOptions sim;
    sim.preset = "figure-eight";
    sim.first_frame = 880;
    sim.end_frame = 1400;
    sim.stride = 2;
    sim.beams = 16;
    sim.seed = 1;
    sim.labels = LabelMode::kNoisy;
    sim.show_progress = false;
    const SimulatedSequence sequence(sim);
    Drive d;
    const Pose tr = sequence.velo_to_cam();
    for (std::size_t k = 0; k < sequence.size(); ++k) {
      d.scans.push_back(sequence.render(k).cloud);
      d.times.push_back(sequence.times()[k]);
      d.truth.push_back(tr.inverse() * sequence.sensor_camera_poses()[k] * tr);
    }
    return d;
  }();
  return drive;
}

struct LoopCount {
  LoopSummary summary;
  std::size_t side_verified = 0;  ///< proposals of a query from the side
  std::size_t side_true = 0;      ///< of those, accepted and true
};

LoopCount slam_loops(double lateral_query_offset) {
  const Drive& drive = figure_eight_end();
  SaloamConfig config;
  config.loop.lateral_query_offset = lateral_query_offset;
  SlamSystem slam(config, std::nullopt);
  for (std::size_t k = 0; k < drive.scans.size(); ++k) slam.process(drive.scans[k], drive.times[k]);
  const LoopTruthOptions truth = LoopTruthOptions::from_config(config.loop);
  LoopCount count;
  count.summary = summarize_loops(slam, drive.truth, truth);
  for (const LoopRecord& loop : slam.loops()) {
    if (loop.query_offset == 0) continue;
    ++count.side_verified;
    count.side_true += loop.verification.accepted && loop_truth(loop, drive.truth, truth).correct;
  }
  const LoopSummary& s = count.summary;
  std::printf("offset %.1f m: %zu loops accepted of %zu verified (%zu true, %zu false); %zu of %zu reverse stretches "
              "closed; from the side: %zu verified, %zu accepted and true\n",
              lateral_query_offset, s.accepted, s.verified, s.accepted_true, s.accepted_false,
              s.reverse_stretches - s.missed_reverse_stretches, s.reverse_stretches, count.side_verified,
              count.side_true);
  return count;
}

TEST(SlamLateralQueries, CloseTheWayBackInTheOppositeLane) {
  const LoopCount from_sensor = slam_loops(0.0);
  const LoopCount from_sides = slam_loops(3.2);
  EXPECT_EQ(from_sensor.side_verified, 0u);
  EXPECT_EQ(from_sensor.summary.accepted_false, 0u);
  EXPECT_EQ(from_sides.summary.accepted_false, 0u);
  // The way back closes from the side, at more of its searches.
  EXPECT_GE(from_sides.side_true, 5u);
  EXPECT_GT(from_sides.summary.accepted_true, from_sensor.summary.accepted_true);
  EXPECT_LE(from_sides.summary.missed_reverse_stretches, from_sensor.summary.missed_reverse_stretches);
}

}  // namespace
}  // namespace saloam
