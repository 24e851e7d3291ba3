// `saloam bench`: odometry speed on a sequence: frequency (median and worst
// frame, excluding disk I/O), time per stage, and peak memory
// (runs/bench_run.hpp).

#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <tuple>

#include <fmt/format.h>

#include "command.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/runs/bench_run.hpp"

namespace saloam::cli {
namespace {

struct BenchOptions {
  SourceArgs source;
  std::optional<std::string> threads;  ///< --threads; else the config's odometry.threads (checked there)
  bool no_semantics = false;
  ConfigOptions config;
};

void print_frequency(const char* what, const Summary& s) {
  std::cout << fmt::format(
      "{} median {:.1f} Hz ({:.1f} ms), 95th percentile {:.1f} Hz ({:.1f} ms), worst frame {:.1f} Hz ({:.1f} ms), "
      "mean {:.1f} ms\n",
      what, 1000.0 / s.median, s.median, 1000.0 / s.p95, s.p95, 1000.0 / s.max, s.max, s.mean);
}

// With one thread the stage's CPU time is its cost, whatever else runs on the machine.
void print_stages(const BenchResult& r, bool cpu_columns) {
  std::cout << "stage (wall)       median ms   mean ms    max ms" << (cpu_columns ? "   cpu: median ms   mean ms" : "")
            << "\n";
  for (const auto& [name, member] : {std::tuple{"features", &FrameTimings::features_ms},
                                     std::tuple{"deskew+downsample", &FrameTimings::deskew_downsample_ms},
                                     std::tuple{"registration", &FrameTimings::registration_ms},
                                     std::tuple{"map update", &FrameTimings::map_update_ms}}) {
    const Summary s = summarize(column(r.stage_wall_ms, member));
    std::cout << fmt::format("{:<18} {:>9.2f} {:>9.2f} {:>9.2f}", name, s.median, s.mean, s.max);
    if (cpu_columns) {
      const Summary c = summarize(column(r.stage_cpu_ms, member));
      std::cout << fmt::format("   {:>14.2f} {:>9.2f}", c.median, c.mean);
    }
    std::cout << "\n";
  }
}

// Stages before the odometry (segmentation) run on threads of their own: the
// pipeline keeps the pace of its slowest stage, the whole run's rate.
void print_source_stages(const BenchResult& r) {
  for (const auto& stage : r.source_stages) {
    const Summary wall = summarize(column(stage.per_frame, &StageTime::wall_ms));
    const Summary cpu = summarize(column(stage.per_frame, &StageTime::cpu_ms));
    std::cout << fmt::format("{} stage (own threads): median {:.1f} ms CPU ({:.1f} Hz on one core), {:.1f} ms wall; "
                             "95th percentile {:.1f} ms CPU\n",
                             stage.name, cpu.median, 1000.0 / cpu.median, wall.median, cpu.p95);
  }
  if (!r.source_stages.empty() && r.run_wall_s > 0)
    std::cout << fmt::format("whole pipeline: {} frames in {:.1f} s ({:.1f} Hz)\n", r.frames, r.run_wall_s,
                             static_cast<double>(r.frames) / r.run_wall_s);
}

int run_bench_command(BenchOptions options) {
  SaloamConfig config = options.config.resolve();
  if (options.threads) apply_config_option(config, "--threads", "odometry.threads", *options.threads);
  const int threads = config.odometry.threads;
  if (options.no_semantics) config.odometry.use_semantics = false;
  options.source.no_calib = true;  // the bench writes no poses: calib.txt is not needed
  const std::unique_ptr<FrameSource> source = options.source.open(!config.odometry.use_semantics, config);
  const BenchResult r = run_bench(*source, config.odometry);
  if (r.frames == 0) return 130;

  std::cout << fmt::format("saloam bench: {} frames of {} ({:.0f} points/scan), threads {}, semantics {}\n", r.frames,
                           options.source.path, r.points_per_scan, threads, r.semantics ? "on" : "off");
  print_frequency("frequency:", summarize(r.frame_wall_ms));
  // CPU time of this thread: on a shared machine wall time includes waiting
  // for a core; with --threads 1 the thread's CPU time is the cost of the frame.
  if (threads == 1) print_frequency("cpu time: ", summarize(r.frame_cpu_ms));
  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) > 0) std::cout << fmt::format("load average {:.2f} (wall time suffers above the core count)\n", load[0]);
  print_stages(r, threads == 1);
  std::cout << fmt::format("per frame (mean): {:.0f} edge + {:.0f} planar features, local map {:.0f} edge + {:.0f} "
                           "planar points, {:.2f} association rounds\n",
                           r.edge_features, r.planar_features, r.map_edge_points, r.map_planar_points,
                           r.association_rounds);
  print_source_stages(r);
  std::cout << fmt::format("peak memory (max RSS): {:.1f} MiB\n", r.peak_rss_mib);
  return 0;
}

const CommandRegistration kRegistration{Command{
    "bench", "Odometry speed (Hz median and worst frame, per stage) and peak memory on a sequence", 80,
    [](CLI::App& app) {
      auto options = std::make_shared<BenchOptions>();
      options->source.add_to(app, "Sequence folder (velodyne/ ...)");
      app.add_option("--threads", options->threads,
                     "Worker threads (1 = single core, 0 = all); default: odometry.threads of the configuration");
      app.add_flag("--no-semantics", options->no_semantics, "Label-agnostic baseline");
      options->config.add_to(app);
      return [options] { return run_bench_command(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
