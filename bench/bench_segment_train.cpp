// Segmentation training speed: one optimisation step of SegNet (forward and
// backward of a batch, Adam's update) on samples of 64 x 512 pixels (the
// trainer's default cut of a 64-beam scan), with and without the Lovasz
// term, on 1 and 2 threads. items_per_second = samples per second. Built
// only with libtorch. `./bench_segment_train`.

#include <benchmark/benchmark.h>

#include <random>

#include "saloam/train/segment_trainer.hpp"
#include "saloam/train/training_run.hpp"

namespace {

using namespace saloam;

std::vector<TrainingSample> samples(int count, int rows, int cols, int channels) {
  std::mt19937_64 rng(1);
  std::normal_distribution<float> value(0.0f, 1.0f);
  std::uniform_int_distribution<std::int64_t> label(0, kNumLearningClasses - 1);
  std::vector<TrainingSample> out(static_cast<std::size_t>(count));
  for (auto& s : out) {
    s.rows = rows;
    s.cols = cols;
    s.image.resize(static_cast<std::size_t>(channels * rows * cols));
    for (auto& v : s.image) v = value(rng);
    s.target.resize(static_cast<std::size_t>(rows * cols));
    for (auto& t : s.target) t = label(rng);
  }
  return out;
}

// Args: batch, threads, Lovasz on (1) or off (0).
void BM_SegmentTrainStep(benchmark::State& state) {
  const int batch = static_cast<int>(state.range(0));
  set_training_threads(static_cast<int>(state.range(1)));
  SegmentTrainOptions options;
  options.lovasz_weight = static_cast<double>(state.range(2));
  SegNetShape shape = options.shape;
  shape.in_channels = 6;
  shape.classes = kNumLearningClasses;
  SegmentTrainer trainer(shape, 1, options);
  const auto data = samples(batch, 64, 512, shape.in_channels);
  for (auto _ : state) benchmark::DoNotOptimize(trainer.step(data, 1e-3));
  state.SetItemsProcessed(state.iterations() * batch);
}
BENCHMARK(BM_SegmentTrainStep)
    ->Args({8, 1, 1})
    ->Args({8, 1, 0})
    ->Args({8, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
