// SegNet's speed: one optimisation step (forward and backward of a batch,
// Adam's update) on samples of 64 x 512 pixels (the trainer's default cut of
// a 64-beam scan), with and without the Lovasz term, on 1 and 2 threads
// (items_per_second = samples per second); and the inference of one whole
// 64 x 2048 image as the plugin runs it (batch norm folded, one thread).
// Built only with libtorch. `./bench_segment_train`.

#include <benchmark/benchmark.h>

#include <random>

#include "saloam/segmentation/torch/segnet.hpp"
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

// Args: widths (w0, w1 = 2 w0, w2 = 4 w0), context blocks.
void BM_SegNetInference(benchmark::State& state) {
  set_training_threads(1);
  SegNetShape shape;
  const int w0 = static_cast<int>(state.range(0));
  shape.widths = {w0, 2 * w0, 4 * w0};
  shape.context_blocks = static_cast<int>(state.range(1));
  shape.in_channels = 6;
  shape.classes = kNumLearningClasses;
  SegNet net(shape);
  net->eval();
  net->fold_batch_norm();
  torch::NoGradGuard no_grad;
  const auto image = torch::randn({1, 6, 64, 2048}).contiguous(torch::MemoryFormat::ChannelsLast);
  for (auto _ : state) benchmark::DoNotOptimize(pixel_classes(net->pixel_logits(image)));
}
BENCHMARK(BM_SegNetInference)->Args({16, 2})->Args({16, 1})->Args({12, 2})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
