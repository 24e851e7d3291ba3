#include "saloam/runs/odometry_run.hpp"

#include <algorithm>
#include <fstream>
#include <numeric>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/runs/output_folder.hpp"
#include "saloam/runs/timing_stats.hpp"
#include "saloam/runs/trajectory_writer.hpp"

namespace saloam {
namespace {

std::vector<double> totals(const std::vector<FrameTimings>& timings) {
  std::vector<double> total;
  total.reserve(timings.size());
  for (const auto& t : timings) total.push_back(t.total_ms());
  return total;
}

}  // namespace

double OdometryRunResult::median_frame_ms() const { return median_of(totals(timings)); }

double OdometryRunResult::worst_frame_ms() const {
  const auto total = totals(timings);
  return total.empty() ? 0.0 : *std::max_element(total.begin(), total.end());
}

void write_timing_json(const std::filesystem::path& file, const std::vector<FrameTimings>& timings) {
  std::vector<double> features, deskew, registration, map;
  for (const auto& t : timings) {
    features.push_back(t.features_ms);
    deskew.push_back(t.deskew_downsample_ms);
    registration.push_back(t.registration_ms);
    map.push_back(t.map_update_ms);
  }
  const auto total = totals(timings);
  const double med = median_of(total);
  const double worst = total.empty() ? 0.0 : *std::max_element(total.begin(), total.end());
  const nlohmann::json j{{"frames", total.size()},
                         {"hz_median", med > 0 ? 1000.0 / med : 0.0},
                         {"hz_worst_frame", worst > 0 ? 1000.0 / worst : 0.0},
                         {"stages",
                          {{"features", stage_stats(features)},
                           {"deskew_downsample", stage_stats(deskew)},
                           {"registration", stage_stats(registration)},
                           {"map_update", stage_stats(map)},
                           {"total", stage_stats(total)}}},
                         {"frame_total_ms", total}};
  std::ofstream out(file);
  if (!out) throw InputError(file, "cannot write timing file");
  out << j.dump(2) << "\n";
}

OdometryRunResult run_odometry(const SequenceReader& reader, const OdometryConfig& config,
                               const std::filesystem::path& out_dir, const OdometryRunOptions& options) {
  const std::size_t first = options.first_frame;
  const std::size_t end = std::min(options.end_frame, reader.size());
  if (first >= end) throw ConfigError(fmt::format("empty frame range {}:{} ({} frames)", first, end, reader.size()));
  if (config.use_semantics && !reader.has_labels()) {
    spdlog::warn("{}: no labels found; running with every point in one class", reader.root().string());
  }

  OdometryRunResult result;
  const std::optional<Pose> tr = output_velo_to_cam(SequenceFolderSource(reader), options.no_calib);
  result.camera_frame = tr.has_value();
  prepare_output_folder(out_dir, reader.root());
  TrajectoryWriter writer(out_dir / "poses.txt", out_dir / "poses_tum.txt", tr);

  SemanticOdometry odometry(config);
  ProgressBar progress(end - first, options.progress_label, options.show_progress);
  for (std::size_t i = first; i < end && !stop_requested(); ++i) {
    const LabelledCloud cloud = reader.load_scan(i);
    const double t = reader.times().at(i);
    const Pose q = odometry.register_frame(cloud, t);
    if (odometry.poses().size() > 1 && !odometry.last_frame_stats().registration.ok) {
      ++result.registration_failures;
      spdlog::warn("frame {}: registration failed (too few correspondences); kept the prediction", i);
    }
    result.output_poses.push_back(writer.write(t, q));
    result.lidar_poses.push_back(q);
    result.timestamps.push_back(t);
    progress.set_status(fmt::format("{:.0f} ms", odometry.timings().back().total_ms()));
    progress.advance();
  }
  progress.finish();
  result.timings = odometry.timings();
  result.frames = result.lidar_poses.size();
  result.interrupted = stop_requested();
  write_timing_json(out_dir / "timing.json", result.timings);
  return result;
}

}  // namespace saloam
