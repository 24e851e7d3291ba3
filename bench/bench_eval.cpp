// Trajectory evaluation speed on KITTI 00 (4541 poses, ORB-SLAM estimate):
// the KITTI devkit metric, ATE with Umeyama, RPE, all at once, the JSON and
// the plot, and reading the two pose files.

#include <benchmark/benchmark.h>

#include <filesystem>

#include "saloam/eval/evaluation_report.hpp"
#include "saloam/eval/trajectory_metrics.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace {

using namespace saloam;

const std::filesystem::path& data_dir() {
  static const std::filesystem::path dir = std::filesystem::path(SALOAM_BENCH_SHARED_DIR) / "data/kitti";
  return dir;
}

const std::vector<Pose>& gt() {
  static const std::vector<Pose> poses = read_trajectory(data_dir() / "poses/00.txt").poses;
  return poses;
}

const std::vector<Pose>& est() {
  static const std::vector<Pose> poses = read_trajectory(data_dir() / "estimates/KITTI_00_ORB.txt").poses;
  return poses;
}

void BM_KittiMetrics_Kitti00(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(compute_kitti_metrics(gt(), est()));
  state.counters["segments"] = static_cast<double>(compute_kitti_metrics(gt(), est()).segments);
}
BENCHMARK(BM_KittiMetrics_Kitti00)->Unit(benchmark::kMillisecond);

void BM_Ate_Kitti00(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(compute_ate(gt(), est(), Alignment::kSE3));
}
BENCHMARK(BM_Ate_Kitti00)->Unit(benchmark::kMillisecond);

void BM_Rpe_Kitti00(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(compute_rpe(gt(), est()));
}
BENCHMARK(BM_Rpe_Kitti00)->Unit(benchmark::kMillisecond);

void BM_EvaluateTrajectories_Kitti00(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(evaluate_trajectories(gt(), est()));
  state.counters["poses"] = static_cast<double>(gt().size());
}
BENCHMARK(BM_EvaluateTrajectories_Kitti00)->Unit(benchmark::kMillisecond);

void BM_ReadTrajectory_Kitti00(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(read_trajectory(data_dir() / "poses/00.txt"));
}
BENCHMARK(BM_ReadTrajectory_Kitti00)->Unit(benchmark::kMillisecond);

void BM_JsonAndPlot_Kitti00(benchmark::State& state) {
  const auto ev = evaluate_trajectories(gt(), est());
  const auto dir = std::filesystem::temp_directory_path() / "saloam_bench_eval";
  for (auto _ : state) {
    write_evaluation_json(dir / "eval.json", ev);
    plot_evaluation(dir / "eval.png", gt(), est(), ev);
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_JsonAndPlot_Kitti00)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
