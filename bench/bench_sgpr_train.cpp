// SGPR training speed: one optimisation step (forward and backward of a
// batch of pairs, each scored in both orders, and Adam's update) at the
// default batch size of `saloam sgpr-train` (16 pairs), on graphs of 40
// nodes (about the size of real KITTI graphs). items_per_second = training
// pairs per second. Built only with libtorch. `./bench_sgpr_train`.

#include <benchmark/benchmark.h>

#include <random>

#include "saloam/train/sgpr_trainer.hpp"
#include "saloam/train/training_run.hpp"

namespace {

std::vector<saloam::SemanticGraph> graphs(int count, int nodes) {
  std::mt19937_64 rng(1);
  std::uniform_int_distribution<int> label(0, saloam::kNumNodeClasses - 1);
  std::uniform_real_distribution<double> xy(-40.0, 40.0), z(-2.0, 4.0);
  std::vector<saloam::SemanticGraph> out(count);
  for (auto& g : out)
    for (int i = 0; i < nodes; ++i) {
      g.nodes.push_back(label(rng));
      g.centers.emplace_back(xy(rng), xy(rng), z(rng));
    }
  return out;
}

void BM_SgprTrainStep(benchmark::State& state) {
  const int batch = static_cast<int>(state.range(0));
  saloam::set_training_threads(static_cast<int>(state.range(1)));
  const auto data = graphs(2 * batch, 40);
  std::vector<const saloam::SemanticGraph*> first, second;
  std::vector<float> targets;
  for (int i = 0; i < batch; ++i) {
    first.push_back(&data[2 * i]);
    second.push_back(&data[2 * i + 1]);
    targets.push_back(i % 2 ? 1.0F : 0.0F);
  }
  saloam::SgprTrainer trainer(1, saloam::SgprOptimizerOptions{});
  for (auto _ : state) benchmark::DoNotOptimize(trainer.step(first, second, targets));
  state.SetItemsProcessed(state.iterations() * batch);
  state.counters["pairs_per_s"] = benchmark::Counter(static_cast<double>(batch), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_SgprTrainStep)->Args({16, 1})->Args({64, 1})->Args({16, 2})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
