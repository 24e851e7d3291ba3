// Simulator speed: world construction along the urban-loop preset and along
// KITTI 00, and one HDL-64E sweep (64/32/16 beams) on 1 and 2 threads.

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <filesystem>

#include "saloam/io/calibration.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/sim/lidar.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sim/trajectories.hpp"
#include "saloam/sim/world.hpp"

namespace {

using namespace saloam;

const std::vector<Pose>& urban_loop() {
  static const std::vector<Pose> poses = preset_trajectory("urban-loop");
  return poses;
}

const World& urban_world() {
  static const World world = build_world(urban_loop(), 1);
  return world;
}

void BM_BuildWorld_UrbanLoop(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(build_world(urban_loop(), 1));
  state.counters["primitives"] = static_cast<double>(urban_world().primitives().size());
}
BENCHMARK(BM_BuildWorld_UrbanLoop)->Unit(benchmark::kMillisecond);

void BM_BuildWorld_Kitti00(benchmark::State& state) {
  const std::filesystem::path dir = std::filesystem::path(SALOAM_BENCH_SHARED_DIR) / "data/kitti";
  const auto camera = read_kitti_poses(dir / "poses/00.txt");
  const auto lidar = camera_to_lidar_poses(camera, read_velo_to_cam(dir / "calib_velo_to_cam.txt", 0));
  for (auto _ : state) benchmark::DoNotOptimize(build_world(lidar, 1));
}
BENCHMARK(BM_BuildWorld_Kitti00)->Unit(benchmark::kMillisecond);

// Args: beams, threads. Time per frame; points per frame as a counter.
void BM_SimulateScan(benchmark::State& state) {
  const int beams = static_cast<int>(state.range(0));
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(1)));
  const World& world = urban_world();
  const LidarModel lidar = LidarModel::hdl64e(beams);
  const SweepRays rays(lidar);
  SimulationOptions options;
  std::size_t frame = 50, points = 0, frames = 0;
  for (auto _ : state) {
    const SweepSpec sweep = sweep_for_frame(urban_loop(), frame, options);
    const SimulatedScan scan = simulate_scan(world, lidar, rays, sweep);
    points += scan.cloud.size();
    ++frames;
    frame = 50 + (frame + 37) % 800;  // different places of the loop
  }
  state.counters["points_per_frame"] = static_cast<double>(points) / static_cast<double>(frames);
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulateScan)->Args({64, 1})->Args({64, 2})->Args({32, 1})->Args({16, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
