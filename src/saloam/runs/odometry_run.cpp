#include "saloam/runs/odometry_run.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/runs/output_folder.hpp"
#include "saloam/runs/stream_report.hpp"
#include "saloam/runs/timing_report.hpp"

namespace saloam {

double OdometryRunResult::median_frame_ms() const { return summarize(column(timings, &FrameTimings::total_ms)).median; }

double OdometryRunResult::worst_frame_ms() const { return summarize(column(timings, &FrameTimings::total_ms)).max; }

void write_timing_json(const std::filesystem::path& file, const std::vector<FrameTimings>& timings,
                       const std::vector<SourceStageTimes>& source_stages) {
  const std::vector<double> total = column(timings, &FrameTimings::total_ms);
  const Summary frame = summarize(total);
  nlohmann::json j{{"frames", total.size()},
                         {"hz_median", hz(frame.median)},
                         {"hz_worst_frame", hz(frame.max)},
                         {"stages",
                          {{"features", stage_stats(column(timings, &FrameTimings::features_ms))},
                           {"deskew_downsample", stage_stats(column(timings, &FrameTimings::deskew_downsample_ms))},
                           {"registration", stage_stats(column(timings, &FrameTimings::registration_ms))},
                           {"map_update", stage_stats(column(timings, &FrameTimings::map_update_ms))},
                           {"total", stage_stats(total)}}},
                         {"frame_total_ms", total}};
  for (const auto& stage : source_stages)
    j["source_stages"][stage.name] = {{"wall", stage_stats(column(stage.per_frame, &StageTime::wall_ms))},
                                      {"cpu", stage_stats(column(stage.per_frame, &StageTime::cpu_ms))}};
  write_file_atomically(file, j.dump(2) + "\n");
}

void warn_no_labels(const SourceInfo& info) {
  spdlog::warn("{}: no labels (no labels/ folder): every point is one class, as with --no-semantics. Pass --segment to "
               "label the scans in-process, --labels DIR for labels made elsewhere, or --no-semantics to say so",
               info.name);
}

OdometryRun::OdometryRun(const OdometryConfig& config, const std::filesystem::path& out_dir,
                         std::optional<Pose> velo_to_cam, bool growing)
    : odometry_(config), writer_(out_dir / "poses.txt", out_dir / "poses_tum.txt", velo_to_cam, growing) {
  result_.camera_frame = velo_to_cam.has_value();
}

bool RegistrationHealth::note(const SemanticOdometry& odometry, std::size_t frame) {
  if (odometry.poses().size() <= 1) return true;  // the first frame has nothing to register to
  const RegistrationResult& r = odometry.last_frame_stats().registration;
  spdlog::debug("frame {}: {} correspondences, smallest normalised eigenvalue {:.4f}", frame, r.correspondences(),
                r.smallest_eigenvalue);
  if (!r.ok) {
    ++failures_;
    in_degenerate_stretch_ = false;
    spdlog::warn("frame {}: registration failed ({} correspondences, too few); kept the constant-velocity prediction",
                 frame, r.correspondences());
    return false;
  }
  if (!r.degenerate()) {
    in_degenerate_stretch_ = false;
    return true;
  }
  ++degenerate_frames_;
  if (!in_degenerate_stretch_) {  // once per stretch of degenerate frames
    spdlog::warn("frame {}: degenerate geometry: {} of 6 directions unconstrained (smallest eigenvalue {:.3g} < "
                 "odometry.degeneracy_eigenvalue {:.3g}); the constant-velocity prediction holds them (counted in "
                 "summary.json until the scene constrains every direction again)",
                 frame, r.degenerate_directions, r.smallest_eigenvalue, odometry.config().degeneracy_eigenvalue);
  }
  in_degenerate_stretch_ = true;
  return true;
}

bool OdometryRun::add(const LabelledCloud& scan, double time, std::size_t frame) {
  const Pose q = odometry_.register_frame(scan, time);
  const bool ok = health_.note(odometry_, frame);
  result_.registration_failures = health_.failures();
  result_.degenerate_frames = health_.degenerate_frames();
  result_.output_poses.push_back(writer_.write(time, q));
  result_.lidar_poses.push_back(q);
  result_.timestamps.push_back(time);
  result_.frames = result_.lidar_poses.size();
  return ok;
}

void OdometryRun::commit() { writer_.commit(); }

namespace {

nlohmann::json odometry_summary(const SourceInfo& info, const OdometryConfig& config, const OdometryRunResult& result) {
  nlohmann::json summary{{"command", "odom"},
                         {"first_frame", info.first_frame},
                         {"frames", result.frames},
                         {"semantics", config.use_semantics && info.has_labels},
                         {"camera_frame", result.camera_frame},
                         {"registration_failures", result.registration_failures},
                         {"degenerate_frames", result.degenerate_frames},
                         {"gravity", gravity_json(result.gravity)}};
  if (info.folder) put_summary_path(summary, "sequence", std::filesystem::absolute(*info.folder).lexically_normal());
  return summary;
}

}  // namespace

OdometryConfig with_source_up(OdometryConfig config, const SourceInfo& info) {
  if (info.imu_up) config.gravity.imu_up = info.imu_up;
  return config;
}

SaloamConfig with_source_up(SaloamConfig config, const SourceInfo& info) {
  config.odometry = with_source_up(std::move(config.odometry), info);
  return config;
}

nlohmann::json gravity_json(const GravityReport& g) {
  nlohmann::json out{{"up", {g.up.x(), g.up.y(), g.up.z()}},
                     {"source", up_source_key(g.source)},
                     {"tilt_deg", g.tilt_deg()},
                     {"votes", g.votes},
                     {"spread_deg", g.spread_deg}};
  if (g.scans_up) out["scans_up_off_deg"] = angle_deg(*g.scans_up, g.up);
  return out;
}

OdometryRunResult run_odometry(FrameSource& source, const OdometryConfig& config, const std::filesystem::path& out_dir,
                               const OdometryRunOptions& options) {
  const SourceInfo& info = source.info();
  if (config.use_semantics && !info.has_labels) warn_no_labels(info);
  const std::optional<Pose> tr = output_velo_to_cam(info);
  OutputFolder folder = open_run_folder(out_dir, info.folder, "odom", kOdometryOutputs);
  OdometryRun run(with_source_up(config, info), out_dir, tr, info.live);
  ProgressBar progress(info.size(), options.progress_label, options.show_progress && !info.live);
  for (std::size_t i = 0; !stop_requested(); ++i) {
    std::optional<SourceFrame> frame = source.next_frame(i);
    if (!frame) break;
    run.add(frame->cloud, frame->time, info.first_frame + i);
    if (options.follow) {
      options.follow(FinishedFrame{.index = i,
                                   .time = frame->time,
                                   .scan = frame->cloud,
                                   .pose = run.odometry().poses().back(),
                                   .corrected = nullptr,
                                   .loops = {}});
    }
    progress.set_status(fmt::format("{:.0f} ms", run.odometry().timings().back().total_ms()));
    progress.advance();
  }
  progress.finish();
  end_live_stream(info);
  run.commit();
  OdometryRunResult result = run.result();
  result.timings = run.odometry().timings();
  result.gravity = run.odometry().gravity();
  result.interrupted = stop_requested();
  write_timing_json(out_dir / "timing.json", result.timings, source.stage_times());
  nlohmann::json summary = odometry_summary(info, config, result);
  report_stream(source, summary);
  write_run_summary(folder, summary);
  result.files = folder.files();
  return result;
}

}  // namespace saloam
