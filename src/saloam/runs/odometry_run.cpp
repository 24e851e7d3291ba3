#include "saloam/runs/odometry_run.hpp"

#include <algorithm>
#include <fstream>
#include <numeric>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/runs/output_folder.hpp"
#include "saloam/runs/timing_stats.hpp"

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

OdometryRun::OdometryRun(const OdometryConfig& config, const std::filesystem::path& out_dir,
                         std::optional<Pose> velo_to_cam)
    : odometry_(config), writer_(out_dir / "poses.txt", out_dir / "poses_tum.txt", velo_to_cam) {
  result_.camera_frame = velo_to_cam.has_value();
}

bool OdometryRun::add(const LabelledCloud& scan, double time) {
  const Pose q = odometry_.register_frame(scan, time);
  const bool ok = odometry_.poses().size() == 1 || odometry_.last_frame_stats().registration.ok;
  if (!ok) ++result_.registration_failures;
  result_.output_poses.push_back(writer_.write(time, q));
  result_.lidar_poses.push_back(q);
  result_.timestamps.push_back(time);
  result_.frames = result_.lidar_poses.size();
  return ok;
}

OdometryRunResult run_odometry(FrameSource& source, const OdometryConfig& config, const std::filesystem::path& out_dir,
                               const OdometryRunOptions& options) {
  const SourceInfo& info = source.info();
  if (config.use_semantics && !info.has_labels) {
    spdlog::warn("{}: no labels found; running with every point in one class", info.name);
  }
  const std::optional<Pose> tr = output_velo_to_cam(info);
  prepare_output_folder(out_dir, info.folder);
  OdometryRun run(config, out_dir, tr);
  ProgressBar progress(info.size(), options.progress_label, options.show_progress);
  for (std::size_t i = 0; i < info.size() && !stop_requested(); ++i) {
    if (!run.add(source.scan(i), info.times.at(i))) {
      spdlog::warn("frame {}: registration failed (too few correspondences); kept the prediction", info.first_frame + i);
    }
    progress.set_status(fmt::format("{:.0f} ms", run.odometry().timings().back().total_ms()));
    progress.advance();
  }
  progress.finish();
  OdometryRunResult result = run.result();
  result.timings = run.odometry().timings();
  result.interrupted = stop_requested();
  write_timing_json(out_dir / "timing.json", result.timings);
  return result;
}

}  // namespace saloam
