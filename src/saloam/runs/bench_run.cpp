#include "saloam/runs/bench_run.hpp"

#include <algorithm>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/core/progress.hpp"

namespace saloam {
namespace {

void add_work(BenchResult& result, const FrameStats& stats) {
  result.edge_features += static_cast<double>(stats.edge_features);
  result.planar_features += static_cast<double>(stats.planar_features);
  result.map_edge_points += static_cast<double>(stats.map_edge_points);
  result.map_planar_points += static_cast<double>(stats.map_planar_points);
  result.association_rounds += stats.association_rounds;
}

void to_means(BenchResult& result) {
  const double n = static_cast<double>(std::max<std::size_t>(result.frames, 1));
  for (double* sum : {&result.points_per_scan, &result.edge_features, &result.planar_features, &result.map_edge_points,
                      &result.map_planar_points, &result.association_rounds}) {
    *sum /= n;
  }
}

}  // namespace

BenchResult run_bench(FrameSource& source, const OdometryConfig& config, bool show_progress) {
  const SourceInfo& info = source.info();
  BenchResult result;
  result.semantics = config.use_semantics && info.has_labels;
  SemanticOdometry odometry(config);
  ProgressBar progress(info.size(), "bench", show_progress);
  const StageTimer run;
  for (std::size_t i = 0; i < info.size() && !stop_requested(); ++i) {
    const LabelledCloud cloud = source.scan(i);  // I/O outside the timed region
    result.points_per_scan += static_cast<double>(cloud.size());
    StageTimer timer;
    odometry.register_frame(cloud, info.times.at(i));
    const StageTime frame = timer.lap();
    result.frame_wall_ms.push_back(frame.wall_ms);
    result.frame_cpu_ms.push_back(frame.cpu_ms);
    add_work(result, odometry.last_frame_stats());
    progress.advance();
  }
  progress.finish();
  result.run_wall_s = run.elapsed_s();
  result.source_stages = source.stage_times();
  result.frames = result.frame_wall_ms.size();
  result.stage_wall_ms = odometry.timings();
  result.stage_cpu_ms = odometry.cpu_timings();
  result.peak_rss_mib = peak_rss_mib();
  result.interrupted = stop_requested();
  to_means(result);
  return result;
}

}  // namespace saloam
