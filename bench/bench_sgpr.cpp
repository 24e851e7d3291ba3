// Place-recognition speed: clustering a simulated 120 k point scan, building
// its semantic graph, SGPR embedding of one graph and batch scoring of 64
// candidates (target: embedding + 64 scores well under 5 ms on one core),
// and Scan Context. Run single-threaded: `./bench_sgpr`.

#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>

#include "saloam/io/scan_io.hpp"
#include "saloam/place/graph_json.hpp"
#include "saloam/place/scan_context.hpp"
#include "saloam/place/semantic_graph.hpp"
#include "saloam/place/sgpr_network.hpp"
#include "saloam/sim/simulator.hpp"

namespace {

const std::filesystem::path kShared = SALOAM_BENCH_SHARED_DIR;

/// One simulated HDL-64E frame with ground-truth labels (urban-loop preset).
const saloam::LabelledCloud& simulated_scan() {
  static const saloam::LabelledCloud cloud = [] {
    const auto dir = std::filesystem::temp_directory_path() / "saloam_bench_sgpr_scan";
    std::filesystem::remove_all(dir);
    saloam::SimulationOptions options;
    options.first_frame = 40;
    options.end_frame = 41;
    options.show_progress = false;
    saloam::simulate_sequence(options, dir);
    auto scan = saloam::read_scan(dir / "velodyne/000000.bin", dir / "labels/000000.label");
    std::filesystem::remove_all(dir);
    return scan;
  }();
  return cloud;
}

const saloam::SgprNetwork& network() {
  static const saloam::SgprNetwork net = saloam::SgprNetwork::load(kShared / "models/sgpr/sgpr_kitti.sgw");
  return net;
}

void BM_ExtractClusters(benchmark::State& state) {
  const auto& cloud = simulated_scan();
  std::size_t clusters = 0;
  for (auto _ : state) {
    const auto c = saloam::extract_clusters(cloud);
    clusters = c.size();
    benchmark::DoNotOptimize(c.data());
  }
  state.counters["points"] = static_cast<double>(cloud.size());
  state.counters["clusters"] = static_cast<double>(clusters);
}
BENCHMARK(BM_ExtractClusters)->Unit(benchmark::kMillisecond);

void BM_BuildGraphWithEdges(benchmark::State& state) {
  const auto& cloud = simulated_scan();
  saloam::SemanticGraph graph;
  for (auto _ : state) {
    graph = saloam::build_semantic_graph(cloud);
    benchmark::DoNotOptimize(graph.nodes.data());
  }
  state.counters["nodes"] = static_cast<double>(graph.size());
  state.counters["edges"] = static_cast<double>(graph.edges.size());
}
BENCHMARK(BM_BuildGraphWithEdges)->Unit(benchmark::kMillisecond);

void BM_SgprEmbed(benchmark::State& state) {
  const auto graph = saloam::read_graph_json(kShared / "models/sgpr/graph_3.json");
  for (auto _ : state) benchmark::DoNotOptimize(network().embed(graph));
}
BENCHMARK(BM_SgprEmbed)->Unit(benchmark::kMicrosecond);

std::vector<saloam::SgprEmbedding> candidates(std::size_t count) {
  std::vector<saloam::SgprEmbedding> stored;
  for (const char* id : {"0", "3", "250"})
    stored.push_back(network().embed(saloam::read_graph_json(kShared / "models/sgpr/" / (std::string("graph_") + id + ".json"))));
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.8F, 1.2F);
  std::vector<saloam::SgprEmbedding> out;
  for (std::size_t i = 0; i < count; ++i) out.push_back(stored[i % 3] * u(rng));
  return out;
}

void BM_SgprScore64Batch(benchmark::State& state) {
  const auto stored = candidates(64);
  for (auto _ : state) benchmark::DoNotOptimize(network().score_batch(stored[0], stored));
}
BENCHMARK(BM_SgprScore64Batch)->Unit(benchmark::kMicrosecond);

void BM_SgprScore64OneByOne(benchmark::State& state) {
  const auto stored = candidates(64);
  for (auto _ : state)
    for (const auto& c : stored) benchmark::DoNotOptimize(network().score(stored[0], c));
}
BENCHMARK(BM_SgprScore64OneByOne)->Unit(benchmark::kMicrosecond);

// The loop-closure query path: embed the new graph once, score it against 64 stored embeddings.
void BM_SgprEmbedAndScore64(benchmark::State& state) {
  const auto graph = saloam::read_graph_json(kShared / "models/sgpr/graph_3.json");
  const auto stored = candidates(64);
  for (auto _ : state) benchmark::DoNotOptimize(network().score_batch(network().embed(graph), stored));
}
BENCHMARK(BM_SgprEmbedAndScore64)->Unit(benchmark::kMicrosecond);

void BM_ScanContextMake(benchmark::State& state) {
  const auto& cloud = simulated_scan();
  for (auto _ : state) benchmark::DoNotOptimize(saloam::make_scan_context(cloud.points));
}
BENCHMARK(BM_ScanContextMake)->Unit(benchmark::kMillisecond);

void BM_ScanContextDistance(benchmark::State& state) {
  const auto& cloud = simulated_scan();
  const auto a = saloam::make_scan_context(cloud.points);
  std::vector<Eigen::Vector3f> shifted;
  for (const auto& p : cloud.points) shifted.emplace_back(p.x() + 2.0F, p.y() - 1.0F, p.z());
  const auto b = saloam::make_scan_context(shifted);
  for (auto _ : state) benchmark::DoNotOptimize(saloam::scan_context_distance(a, b));
}
BENCHMARK(BM_ScanContextDistance)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
