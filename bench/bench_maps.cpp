// Saved maps and localisation in them (docs/map_format.md), on two passes
// through one simulated world (the demo route, 64 beams, noisy labels):
// pass 0 (route poses 0:400) is mapped by the SLAM once, pass 1 (route
// 100:220, driven at another time) is localised in that map. Timed:
// writing the map, reading it (manifest, keyframes, descriptors) and one
// keyframe's features (a cache miss), relocalising from no prior, and a
// tracked frame. (Memory is measured through the CLI, docs/map_format.md:
// here the fixture's scans, all in memory, would dominate it.)

#include <filesystem>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

#include <benchmark/benchmark.h>
#include <spdlog/spdlog.h>

#include "saloam/maps/localizer.hpp"
#include "saloam/maps/prior_map.hpp"
#include "saloam/maps/slam_map.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/slam/slam_system.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

SimulationOptions pass_options(std::size_t pass) {
  SimulationOptions sim;
  sim.preset = "figure-eight";
  sim.passes = {RoutePass{0, 400, false}, RoutePass{100, 220, false}};
  sim.pass = pass;
  sim.beams = 64;
  sim.seed = 1;
  sim.labels = LabelMode::kNoisy;
  sim.show_progress = false;
  return sim;
}

struct Scans {
  std::vector<LabelledCloud> clouds;
  std::vector<double> times;
};

Scans render_pass(std::size_t pass) {
  const SimulatedSequence sequence(pass_options(pass));
  Scans scans;
  for (std::size_t k = 0; k < sequence.size(); ++k) {
    scans.clouds.push_back(sequence.render(k).cloud);
    scans.times.push_back(sequence.times()[k]);
  }
  return scans;
}

// Pass 0's SLAM, its map written once into a folder of this process, and
// pass 1's scans.
struct Fixture {
  SaloamConfig config;
  fs::path folder = fs::temp_directory_path() / ("saloam_bench_maps_" + std::to_string(::getpid()));
  std::unique_ptr<SlamSystem> slam;
  Scans pass1;

  Fixture() {
    spdlog::set_level(spdlog::level::warn);  // no line per relocalisation
    const Scans pass0 = render_pass(0);
    slam = std::make_unique<SlamSystem>(config, std::nullopt);
    for (std::size_t k = 0; k < pass0.clouds.size(); ++k) slam->process(pass0.clouds[k], pass0.times[k]);
    write_slam_map(map(), *slam, config, MapManifest{});
    pass1 = render_pass(1);
  }
  ~Fixture() {
    std::error_code ec;
    fs::remove_all(folder, ec);
  }
  [[nodiscard]] fs::path map() const { return folder / "map"; }
  [[nodiscard]] std::size_t cached() const { return static_cast<std::size_t>(config.localize.cached_keyframes); }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

std::uintmax_t folder_bytes(const fs::path& folder) {
  std::uintmax_t bytes = 0;
  for (const auto& entry : fs::recursive_directory_iterator(folder))
    if (entry.is_regular_file()) bytes += entry.file_size();
  return bytes;
}

void BM_MapWrite(benchmark::State& state) {
  Fixture& f = fixture();
  const fs::path out = f.folder / "written";
  for (auto _ : state) {
    state.PauseTiming();
    fs::remove_all(out);
    state.ResumeTiming();
    write_slam_map(out, *f.slam, f.config, MapManifest{});
  }
  state.counters["keyframes"] = static_cast<double>(f.slam->keyframes().size());
  state.counters["MB"] = static_cast<double>(folder_bytes(out)) / 1e6;
}
BENCHMARK(BM_MapWrite)->Unit(benchmark::kMillisecond);

// What `localize` reads before its first frame: the manifest, the keyframes'
// poses and the place descriptors (features are read on demand).
void BM_MapOpen(benchmark::State& state) {
  Fixture& f = fixture();
  for (auto _ : state) {
    PriorMap map = PriorMap::open(f.map(), f.cached());
    benchmark::DoNotOptimize(map.size());
  }
}
BENCHMARK(BM_MapOpen)->Unit(benchmark::kMillisecond);

// One keyframe's features read from disk and checked (a cache miss).
void BM_MapReadKeyframeFeatures(benchmark::State& state) {
  Fixture& f = fixture();
  const PriorMap map = PriorMap::open(f.map(), 1);
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(map.features(k));
    k = (k + 1) % map.size();  // a cache of one: every call reads
  }
  state.counters["loads"] = static_cast<double>(map.loads());
}
BENCHMARK(BM_MapReadKeyframeFeatures)->Unit(benchmark::kMillisecond);

// From no prior to placed: pass 1's frames from its start until the
// relocalisation is confirmed (place recognition over the whole map, the
// verification, two confirming fixes), odometry included.
void BM_RelocalizeFromNoPrior(benchmark::State& state) {
  Fixture& f = fixture();
  const PriorMap map = PriorMap::open(f.map(), f.cached());
  std::size_t frames = 0;
  bool placed = false;
  for (auto _ : state) {
    Localizer localizer(f.config, map, std::nullopt);
    for (frames = 0; frames < f.pass1.clouds.size() && !localizer.first_placed_at(); ++frames) {
      localizer.process(f.pass1.clouds[frames], f.pass1.times[frames]);
    }
    placed = localizer.first_placed_at().has_value();
  }
  state.counters["frames_to_place"] = static_cast<double>(frames);
  state.counters["placed"] = placed ? 1.0 : 0.0;
}
BENCHMARK(BM_RelocalizeFromNoPrior)->Unit(benchmark::kMillisecond);

// One frame once placed: odometry, and every localize.track_every-th frame a
// fit against the map near the prediction.
void BM_LocalizeTrackedFrame(benchmark::State& state) {
  Fixture& f = fixture();
  const PriorMap map = PriorMap::open(f.map(), f.cached());
  std::unique_ptr<Localizer> localizer;
  std::size_t next = f.pass1.clouds.size();
  std::size_t tracked = 0, timed = 0;
  for (auto _ : state) {
    if (next == f.pass1.clouds.size()) {  // (re)start: placed again before timing
      state.PauseTiming();
      localizer = std::make_unique<Localizer>(f.config, map, std::nullopt);
      for (next = 0; next < f.pass1.clouds.size() && !localizer->first_placed_at(); ++next) {
        localizer->process(f.pass1.clouds[next], f.pass1.times[next]);
      }
      state.ResumeTiming();
      if (next == f.pass1.clouds.size()) {
        state.SkipWithError("pass 1 was never placed in the map");
        break;
      }
    }
    const LocalizedFrame& frame = localizer->process(f.pass1.clouds[next], f.pass1.times[next]);
    ++next;
    ++timed;
    if (frame.status == LocalizationStatus::kLocalized) ++tracked;
  }
  state.counters["localized_share"] = timed > 0 ? static_cast<double>(tracked) / static_cast<double>(timed) : 0.0;
}
BENCHMARK(BM_LocalizeTrackedFrame)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace saloam

BENCHMARK_MAIN();
