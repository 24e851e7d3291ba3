// Odometry speed on the real KITTI scans (shared/data/kitti/scans_00):
// feature extraction, local-map update (incremental neighbour grid; kd-tree
// rebuild and nanoflann's dynamic index for comparison),
// registration and the whole pipeline per frame, single-threaded unless
// stated. Peak memory is reported as a counter (max RSS, core/profiling.hpp).

#include <cstdio>
#include <deque>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

// nanoflann 1.4's dynamic index trips GCC 12's -Wmaybe-uninitialized inside
// its header (root_bbox); the pragma state at the header's lines decides.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <nanoflann.hpp>
#pragma GCC diagnostic pop

#include "saloam/core/profiling.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/odometry/semantic_odometry.hpp"

namespace saloam {
namespace {

const std::vector<LabelledCloud>& scans() {
  static const std::vector<LabelledCloud> data = [] {
    std::vector<LabelledCloud> out;
    for (int i = 0; i < 6; ++i) {
      char name[64];
      std::snprintf(name, sizeof(name), "/data/kitti/scans_00/%06d.bin", i);
      out.push_back(read_scan(std::string(SALOAM_BENCH_SHARED_DIR) + name));
    }
    return out;
  }();
  return data;
}

OdometryConfig kitti_config() {
  OdometryConfig config;
  config.features.pose_time_in_sweep = 0.05;
  return config;
}

void BM_ExtractFeatures(benchmark::State& state) {
  const auto config = kitti_config();
  std::size_t i = 0;
  for (auto _ : state) {
    auto f = extract_features(scans()[i++ % scans().size()], config.features, false);
    benchmark::DoNotOptimize(f);
  }
  state.counters["points"] = static_cast<double>(scans()[0].size());
}
BENCHMARK(BM_ExtractFeatures)->Unit(benchmark::kMillisecond);

// Local map of N_m = 20 frames: adding one frame (and dropping the oldest).
void BM_LocalMapUpdate(benchmark::State& state) {
  const auto config = kitti_config();
  const auto sizes = class_voxel_sizes(config);
  std::vector<ScanFeatures> features;
  for (const auto& s : scans()) {
    auto f = extract_features(s, config.features, false);
    f.edges = voxel_downsample(f.edges, sizes);
    f.planars = voxel_downsample(f.planars, sizes);
    features.push_back(std::move(f));
  }
  SemanticLocalMap map(config.local_map_frames, sizes, config.max_correspondence_distance);
  // Fill the map with 20 frames (shifted copies) before timing.
  for (int k = 0; k < config.local_map_frames; ++k) {
    auto f = features[k % features.size()];
    for (auto& p : f.planars.points) p.x() += 0.7 * k;
    for (auto& p : f.edges.points) p.x() += 0.7 * k;
    map.add_frame(f.edges, f.planars);
  }
  int k = config.local_map_frames;
  for (auto _ : state) {
    auto f = features[k % features.size()];
    for (auto& p : f.planars.points) p.x() += 0.7 * k;
    for (auto& p : f.edges.points) p.x() += 0.7 * k;
    ++k;
    map.add_frame(std::move(f.edges), std::move(f.planars));
  }
  state.counters["map_points"] = static_cast<double>(map.num_edge_points() + map.num_planar_points());
}
BENCHMARK(BM_LocalMapUpdate)->Unit(benchmark::kMillisecond);

// Local-map neighbour search, three ways: a map of 20 frames of
// ~2000 planar points; per frame one frame is added and the oldest removed,
// then 6000 5-NN queries (the registration's load for one outer iteration).
// Static: rebuild a nanoflann kd-tree from scratch each frame. Dynamic:
// nanoflann's KDTreeSingleIndexDynamicAdaptor (addPoints, lazy removePoint,
// log(n) trees). Grid: the NeighbourGrid the local map uses (below).
struct PointStore {
  std::vector<Eigen::Vector3d> pts;
  [[nodiscard]] std::size_t kdtree_get_point_count() const { return pts.size(); }
  [[nodiscard]] double kdtree_get_pt(std::size_t i, std::size_t d) const { return pts[i][static_cast<int>(d)]; }
  template <class B>
  bool kdtree_get_bbox(B&) const { return false; }
};
std::vector<Eigen::Vector3d> random_frame(std::mt19937& rng, int k) {
  std::uniform_real_distribution<double> u(-40.0, 40.0);
  std::vector<Eigen::Vector3d> f(2000);
  for (auto& p : f) p = Eigen::Vector3d(u(rng) + 0.7 * k, u(rng), 0.005 * u(rng));  // a 0.4 m thick slab
  return f;
}
// Queries spread over the current window (frames move 0.7 m along x each).
void run_queries(benchmark::State& state, const auto& tree, std::mt19937& rng, int frame) {
  std::uniform_real_distribution<double> u(-40.0, 40.0);
  const double x0 = 0.7 * (frame - 10);
  std::uint32_t idx[5];
  double d2[5];
  for (int q = 0; q < 6000; ++q) {
    const Eigen::Vector3d p(x0 + u(rng), u(rng), 0.0);
    nanoflann::KNNResultSet<double, std::uint32_t> result(5);
    result.init(idx, d2);
    tree.findNeighbors(result, p.data(), nanoflann::SearchParams());
    benchmark::DoNotOptimize(d2[0]);
  }
  (void)state;
}
void BM_MapTreeRebuild(benchmark::State& state) {
  std::mt19937 rng(1);
  std::deque<std::vector<Eigen::Vector3d>> frames;
  int k = 0;
  for (; k < 20; ++k) frames.push_back(random_frame(rng, k));
  PointStore store;
  for (auto _ : state) {
    frames.pop_front();
    frames.push_back(random_frame(rng, k++));
    store.pts.clear();
    for (const auto& f : frames) store.pts.insert(store.pts.end(), f.begin(), f.end());
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointStore>, PointStore, 3, std::uint32_t>
        tree(3, store, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    tree.buildIndex();
    run_queries(state, tree, rng, k);
  }
}
BENCHMARK(BM_MapTreeRebuild)->Unit(benchmark::kMillisecond);
void BM_MapTreeDynamic(benchmark::State& state) {
  std::mt19937 rng(1);
  PointStore store;
  using Tree = nanoflann::KDTreeSingleIndexDynamicAdaptor<nanoflann::L2_Simple_Adaptor<double, PointStore>, PointStore, 3,
                                                          std::uint32_t>;
  Tree tree(3, store, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  int k = 0;
  for (; k < 20; ++k) {
    const auto f = random_frame(rng, k);
    const auto start = static_cast<std::uint32_t>(store.pts.size());
    store.pts.insert(store.pts.end(), f.begin(), f.end());
    tree.addPoints(start, static_cast<std::uint32_t>(store.pts.size() - 1));
  }
  for (auto _ : state) {
    // Points are never compacted: the store keeps the removed frames.
    const auto oldest = static_cast<std::size_t>(k - 20) * 2000;
    for (std::size_t i = oldest; i < oldest + 2000; ++i) tree.removePoint(i);
    const auto f = random_frame(rng, k++);
    const auto start = static_cast<std::uint32_t>(store.pts.size());
    store.pts.insert(store.pts.end(), f.begin(), f.end());
    tree.addPoints(start, static_cast<std::uint32_t>(store.pts.size() - 1));
    run_queries(state, tree, rng, k);
  }
}
BENCHMARK(BM_MapTreeDynamic)->Unit(benchmark::kMillisecond);
// The structure the local map uses: points hashed into cells (2 m for a 1 m
// search radius), updated point by point (insert the new frame, erase the
// oldest), 5-NN within 1 m.
void BM_NeighbourGrid(benchmark::State& state) {
  std::mt19937 rng(1);
  std::deque<std::vector<Eigen::Vector3d>> frames;
  NeighbourGrid grid(1.0);
  int k = 0;
  for (; k < 20; ++k) {
    frames.push_back(random_frame(rng, k));
    for (const auto& p : frames.back()) grid.insert(p, 0);
  }
  std::uniform_real_distribution<double> u(-40.0, 40.0);
  std::array<Eigen::Vector3d, 5> nb;
  std::array<double, 5> d2{};
  std::size_t found = 0;
  for (auto _ : state) {
    for (const auto& p : frames.front()) grid.erase(p, 0);
    frames.pop_front();
    frames.push_back(random_frame(rng, k++));
    for (const auto& p : frames.back()) grid.insert(p, 0);
    const double x0 = 0.7 * (k - 10);
    for (int q = 0; q < 6000; ++q) {
      const Eigen::Vector3d p(x0 + u(rng), u(rng), 0.0);
      found += static_cast<std::size_t>(grid.nearest(p, 0, 5, 1.0, nb.data(), d2.data()) == 5);
      benchmark::DoNotOptimize(d2[0]);
    }
  }
  state.counters["found_5_within_1m"] = static_cast<double>(found) / (6000.0 * static_cast<double>(state.iterations()));
}
BENCHMARK(BM_NeighbourGrid)->Unit(benchmark::kMillisecond);

// The whole pipeline per frame (features, de-skew, registration, map
// update) over the six real scans, fresh pipeline each pass (so the local map
// holds at most 5 frames: `saloam bench` on a long sequence gives the steady
// state with N_m = 20); threads = argument. Time per frame.
void BM_PipelineFrame(benchmark::State& state) {
  auto config = kitti_config();
  config.threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    SemanticOdometry odometry(config);
    for (int i = 0; i < 6; ++i) odometry.register_frame(scans()[i], 0.1 * i);
    benchmark::DoNotOptimize(odometry.poses().back());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * 6);
  state.counters["ms_per_frame"] = benchmark::Counter(static_cast<double>(state.iterations()) * 6 / 1000.0,
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["peak_rss_MiB"] = peak_rss_mib();
}
BENCHMARK(BM_PipelineFrame)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace saloam

BENCHMARK_MAIN();
