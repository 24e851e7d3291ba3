// Segmentation speed on one core: the stages of Segmenter::labels on a
// simulated 64-beam HDL-64E scan (rings, projection, network, k-nearest-
// neighbour vote) and the whole stage, for 64/32/16 beams. Scans come as a
// KITTI .bin file gives them (rings from the storage order; second argument
// 0) or with a ring field as PCD, PLY and bags give them (1). The network is
// the shipped model (models/segmenter/saloam.yaml) or $SALOAM_BENCH_SEGMENTER;
// the network benchmarks are skipped when there is none or when this build
// has no network plugin (no libtorch).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <filesystem>

#include "saloam/segmentation/knn_labels.hpp"
#include "saloam/segmentation/segmenter.hpp"
#include "saloam/sim/lidar.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sim/trajectories.hpp"
#include "saloam/sim/world.hpp"

namespace {

using namespace saloam;
namespace fs = std::filesystem;

const LabelledCloud& simulated_scan(int beams) {
  static std::map<int, LabelledCloud> scans;
  if (auto it = scans.find(beams); it != scans.end()) return it->second;
  SimulationOptions options;
  options.preset = "urban-loop";
  options.first_frame = 40;
  options.end_frame = 41;
  options.beams = beams;
  options.show_progress = false;
  const SimulatedSequence sequence(options);
  return scans.emplace(beams, sequence.render(0).cloud).first->second;
}

/// The simulated scan with its ring field (with_ring_field) or without.
const LabelledCloud& scan(int beams, bool with_ring_field = false) {
  static std::map<int, LabelledCloud> stripped;
  const LabelledCloud& cloud = simulated_scan(beams);
  if (with_ring_field) return cloud;
  if (auto it = stripped.find(beams); it != stripped.end()) return it->second;
  LabelledCloud copy = cloud;
  copy.ring.clear();
  return stripped.emplace(beams, std::move(copy)).first->second;
}

fs::path model_description() {
  if (const char* env = std::getenv("SALOAM_BENCH_SEGMENTER"); env && *env) return env;
  return fs::path(SALOAM_BENCH_SOURCE_DIR) / "models/segmenter/saloam.yaml";
}

const Segmenter* segmenter() {
  static const std::unique_ptr<Segmenter> loaded = []() -> std::unique_ptr<Segmenter> {
    try {
      return std::make_unique<Segmenter>(read_segmenter_spec(model_description()), SALOAM_BENCH_PLUGIN);
    } catch (const std::exception&) {
      return nullptr;
    }
  }();
  return loaded.get();
}

void BM_PointRings(benchmark::State& state) {
  const LabelledCloud& cloud = scan(static_cast<int>(state.range(0)), state.range(1) != 0);
  for (auto _ : state) benchmark::DoNotOptimize(point_rings(cloud, FeatureConfig{}));
}
BENCHMARK(BM_PointRings)->Args({64, 0})->Args({64, 1})->Unit(benchmark::kMillisecond);

void BM_ProjectScan(benchmark::State& state) {
  const LabelledCloud& cloud = scan(64);
  const PointRings rings = point_rings(cloud, FeatureConfig{});
  ProjectionSpec spec;
  spec.columns = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(project_scan(cloud, rings.ring, rings.beams, spec));
}
BENCHMARK(BM_ProjectScan)->Arg(2048)->Unit(benchmark::kMillisecond);

void BM_KnnVote(benchmark::State& state) {
  const LabelledCloud& cloud = scan(64);
  const PointRings rings = point_rings(cloud, FeatureConfig{});
  const RangeImage image = project_scan(cloud, rings.ring, rings.beams, ProjectionSpec{});
  std::vector<std::int16_t> pixel_class(image.pixels());
  for (std::size_t p = 0; p < pixel_class.size(); ++p)
    pixel_class[p] = image.shown[p] < 0 ? 0 : static_cast<std::int16_t>(1 + cloud.label[image.shown[p]] % 19);
  const auto ranges = point_ranges(cloud);
  KnnOptions options;
  options.k = static_cast<int>(state.range(0));
  options.window = static_cast<int>(state.range(1));
  for (auto _ : state) benchmark::DoNotOptimize(point_classes(image, pixel_class, ranges, 20, options));
}
// (k, window): RangeNet++'s 5 x 5 up to the shipped models' 17 of 11 x 11.
BENCHMARK(BM_KnnVote)->Args({5, 5})->Args({9, 7})->Args({13, 9})->Args({17, 11})->Unit(benchmark::kMillisecond);

// The whole stage (rings, projection, network, vote) on one thread; args:
// beams, ring field.
void BM_SegmentScan(benchmark::State& state) {
  const Segmenter* s = segmenter();
  if (s == nullptr) {
    state.SkipWithError("no segmentation model or no network plugin");
    return;
  }
  const int beams = static_cast<int>(state.range(0));
  const bool ring_field = state.range(1) != 0;
  const auto& accepted = s->spec().beams;
  if (s->spec().projection.row_mode == RowMode::kRing && std::find(accepted.begin(), accepted.end(), beams) == accepted.end()) {
    state.SkipWithError("the model does not take this beam count");
    return;
  }
  const LabelledCloud& cloud = scan(beams, ring_field);
  for (auto _ : state) benchmark::DoNotOptimize(s->labels(cloud));
  state.counters["points"] = static_cast<double>(cloud.size());
}
BENCHMARK(BM_SegmentScan)
    ->Args({64, 0})
    ->Args({32, 0})
    ->Args({16, 0})
    ->Args({64, 1})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
