// The live view's cost to a run (`--serve`, viewer/live_view.hpp): what the
// run's thread pays per frame (the newest scan kept, a piece of the map every
// 2 m) on 64-beam scans of the urban loop, 1 m a frame; and what one poll
// costs the server after loop closure moved a 4,500-frame trajectory (every
// pose sent again).

#include <vector>

#include <benchmark/benchmark.h>

#include "saloam/sim/simulator.hpp"
#include "saloam/viewer/live_view.hpp"

namespace saloam {
namespace {

const std::vector<LabelledCloud>& scans() {
  static const std::vector<LabelledCloud> clouds = [] {
    SimulationOptions sim;
    sim.preset = "urban-loop";
    sim.end_frame = 10;
    sim.beams = 64;
    sim.seed = 1;
    sim.show_progress = false;
    const SimulatedSequence sequence(sim);
    std::vector<LabelledCloud> out;
    for (std::size_t k = 0; k < sequence.size(); ++k) out.push_back(sequence.render(k).cloud);
    return out;
  }();
  return clouds;
}

void BM_LiveViewAddFrame_64Beams(benchmark::State& state) {
  const auto& clouds = scans();
  LiveView view("bench", "slam");
  Pose pose = Pose::Identity();
  std::size_t frame = 0;
  for (auto _ : state) {
    pose.translation().x() += 1.0;  // a piece of the map every second frame
    view.add_frame(pose, clouds[frame++ % clouds.size()]);
  }
  state.counters["points_per_scan"] = static_cast<double>(clouds.front().size());
  state.counters["pieces"] = static_cast<double>(view.chunks());
}
BENCHMARK(BM_LiveViewAddFrame_64Beams)->Unit(benchmark::kMicrosecond)->Iterations(400);

void BM_LiveViewPollAfterLoopClosure_4500Frames(benchmark::State& state) {
  LiveView view("bench", "slam");
  const LabelledCloud empty;
  std::vector<Pose> poses(4500, Pose::Identity());
  for (std::size_t f = 0; f < poses.size(); ++f) {
    poses[f].translation().x() = static_cast<double>(f);
    view.add_frame(poses[f], empty);
  }
  view.replace_poses(poses);
  std::size_t bytes = 0;
  for (auto _ : state) bytes = view.state_json(0, poses.size()).size();
  state.counters["bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_LiveViewPollAfterLoopClosure_4500Frames)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace saloam

BENCHMARK_MAIN();
