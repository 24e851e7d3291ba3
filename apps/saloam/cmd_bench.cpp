// `saloam bench`: odometry speed on a sequence: frequency (median and worst
// frame, excluding disk I/O), time per stage, and peak memory (getrusage).

#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <cstdlib>
#include <chrono>
#include <iostream>
#include <memory>
#include <numeric>
#include <tuple>

#include <fmt/format.h>

#include "command.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/runs/odometry_run.hpp"
#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/odometry/semantic_odometry.hpp"

namespace saloam::cli {
namespace {

struct BenchOptions {
  std::string sequence;
  std::string frames;
  std::string labels;
  int threads = 1;
  bool no_semantics = false;
  ConfigOptions config;
};

struct Summary {
  double median = 0, p95 = 0, mean = 0, max = 0;
};
Summary summarize(std::vector<double> v) {
  Summary s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.median = v[v.size() / 2];
  s.p95 = v[std::min(v.size() - 1, v.size() * 95 / 100)];
  s.mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  s.max = v.back();
  return s;
}

int run_bench(const BenchOptions& options) {
  SaloamConfig config = options.config.resolve();
  config.odometry.threads = options.threads;
  if (options.no_semantics) config.odometry.use_semantics = false;
  SequenceOptions seq_options;
  if (!options.labels.empty()) seq_options.labels_dir = options.labels;
  seq_options.ignore_labels = !config.odometry.use_semantics;
  const SequenceReader reader(options.sequence, seq_options);
  const auto [first, last] = FrameRange::parse(options.frames).clip(reader.size());

  SemanticOdometry odometry(config.odometry);
  std::vector<double> wall_ms, cpu_ms;
  // CPU time of this thread: on a shared machine wall time includes waiting
  // for a core; with --threads 1 the thread's CPU time is the cost of the frame.
  auto thread_cpu_ms = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
  };
  std::size_t points = 0;
  // Work per frame, to explain the timings: features after downsampling,
  // local-map size and association rounds (neighbour queries of every feature).
  double edges = 0, planars = 0, map_edges = 0, map_planars = 0, rounds = 0;
  ProgressBar progress(last - first, "bench");
  for (std::size_t i = first; i < last && !stop_requested(); ++i) {
    const LabelledCloud cloud = reader.load_scan(i);  // I/O outside the timed region
    points += cloud.size();
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = thread_cpu_ms();
    odometry.register_frame(cloud, reader.times().at(i));
    cpu_ms.push_back(thread_cpu_ms() - c0);
    wall_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    const FrameStats& stats = odometry.last_frame_stats();
    edges += static_cast<double>(stats.edge_features);
    planars += static_cast<double>(stats.planar_features);
    map_edges += static_cast<double>(stats.map_edge_points);
    map_planars += static_cast<double>(stats.map_planar_points);
    rounds += stats.association_rounds;
    progress.advance();
  }
  progress.finish();
  if (wall_ms.empty()) return 130;

  struct StageTimes {
    std::vector<double> features, deskew, registration, map;
  };
  auto stage_times = [](const std::vector<FrameTimings>& timings) {
    StageTimes s;
    for (const auto& t : timings) {
      s.features.push_back(t.features_ms);
      s.deskew.push_back(t.deskew_downsample_ms);
      s.registration.push_back(t.registration_ms);
      s.map.push_back(t.map_update_ms);
    }
    return s;
  };
  const StageTimes wall_stages = stage_times(odometry.timings());
  const StageTimes cpu_stages = stage_times(odometry.cpu_timings());
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const Summary total = summarize(wall_ms);
  std::cout << fmt::format("saloam bench: {} frames of {} ({:.0f} points/scan), threads {}, semantics {}\n",
                           wall_ms.size(), options.sequence, static_cast<double>(points) / wall_ms.size(),
                           options.threads, config.odometry.use_semantics && reader.has_labels() ? "on" : "off");
  std::cout << fmt::format(
      "frequency: median {:.1f} Hz ({:.1f} ms), 95th percentile {:.1f} Hz ({:.1f} ms), worst frame {:.1f} Hz ({:.1f} ms), "
      "mean {:.1f} ms\n",
      1000.0 / total.median, total.median, 1000.0 / total.p95, total.p95, 1000.0 / total.max, total.max, total.mean);
  if (options.threads == 1) {
    const Summary cpu = summarize(cpu_ms);
    std::cout << fmt::format(
        "cpu time:  median {:.1f} Hz ({:.1f} ms), 95th percentile {:.1f} Hz ({:.1f} ms), worst frame {:.1f} Hz ({:.1f} ms), "
        "mean {:.1f} ms\n",
        1000.0 / cpu.median, cpu.median, 1000.0 / cpu.p95, cpu.p95, 1000.0 / cpu.max, cpu.max, cpu.mean);
  }
  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) > 0) std::cout << fmt::format("load average {:.2f} (wall time suffers above the core count)\n", load[0]);
  // With one thread the stage's CPU time is its cost, whatever else runs on the machine.
  const bool cpu_columns = options.threads == 1;
  std::cout << "stage (wall)       median ms   mean ms    max ms" << (cpu_columns ? "   cpu: median ms   mean ms" : "")
            << "\n";
  for (const auto& [name, wall, cpu] :
       {std::tuple{"features", &wall_stages.features, &cpu_stages.features},
        std::tuple{"deskew+downsample", &wall_stages.deskew, &cpu_stages.deskew},
        std::tuple{"registration", &wall_stages.registration, &cpu_stages.registration},
        std::tuple{"map update", &wall_stages.map, &cpu_stages.map}}) {
    const Summary s = summarize(*wall);
    std::cout << fmt::format("{:<18} {:>9.2f} {:>9.2f} {:>9.2f}", name, s.median, s.mean, s.max);
    if (cpu_columns) {
      const Summary c = summarize(*cpu);
      std::cout << fmt::format("   {:>14.2f} {:>9.2f}", c.median, c.mean);
    }
    std::cout << "\n";
  }
  const double n = static_cast<double>(wall_ms.size());
  std::cout << fmt::format("per frame (mean): {:.0f} edge + {:.0f} planar features, local map {:.0f} edge + {:.0f} "
                           "planar points, {:.2f} association rounds\n",
                           edges / n, planars / n, map_edges / n, map_planars / n, rounds / n);
  std::cout << fmt::format("peak memory (max RSS): {:.1f} MiB\n", usage.ru_maxrss / 1024.0);
  return 0;
}

const CommandRegistration kRegistration{Command{
    "bench", "Odometry speed (Hz median and worst frame, per stage) and peak memory on a sequence", 80,
    [](CLI::App& app) {
      auto options = std::make_shared<BenchOptions>();
      app.add_option("SEQ_DIR", options->sequence, "Sequence folder (velodyne/ ...)")->required();
      app.add_option("--frames", options->frames, "Frame range A:B (B exclusive)");
      app.add_option("--threads", options->threads, "Worker threads (1 = single core, 0 = all)")
          ->capture_default_str();
      app.add_option("--labels", options->labels, "Folder of .label files to use instead of SEQ_DIR/labels");
      app.add_flag("--no-semantics", options->no_semantics, "Label-agnostic baseline");
      options->config.add_to(app);
      return [options] { return run_bench(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
