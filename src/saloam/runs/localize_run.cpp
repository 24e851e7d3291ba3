#include "saloam/runs/localize_run.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/eval/trajectory_metrics.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/runs/loop_truth.hpp"
#include "saloam/runs/odometry_run.hpp"
#include "saloam/runs/output_folder.hpp"
#include "saloam/runs/stream_report.hpp"
#include "saloam/runs/session_eval.hpp"
#include "saloam/runs/timing_report.hpp"
#include "saloam/runs/trajectory_writer.hpp"

namespace saloam {

namespace {

// The source's reference poses of the processed frames, LiDAR frame, frame 0 = identity.
std::optional<std::vector<Pose>> reference_lidar_poses(const SourceInfo& info, std::size_t frames) {
  const auto& camera = info.sensor_camera_poses ? info.sensor_camera_poses : info.camera_poses;
  if (!camera || camera->size() < frames || frames == 0) return std::nullopt;
  std::vector<Pose> poses(camera->begin(), camera->begin() + static_cast<std::ptrdiff_t>(frames));
  if (info.velo_to_cam) poses = camera_to_lidar_poses(poses, *info.velo_to_cam);
  const Pose rebase = poses.front().inverse();
  for (auto& p : poses) p = orthonormalized(rebase * p);
  return poses;
}

std::string number_or_empty(double v, int digits) { return v < 0 ? std::string() : fmt::format("{:.{}f}", v, digits); }

/// An estimate as it is compared with the truth: moved by the map's own
/// error (LocalizeRunOptions::map_error) when known. Every error this
/// run reports (summary, frames.csv, relocalizations.csv) is measured so.
Pose for_truth(const Pose& estimate, const LocalizeRunOptions& options) {
  return options.map_error ? Pose(options.map_error->alignment * estimate) : estimate;
}

/// [m] how far `estimate` (for_truth) lies from `truth`.
double truth_error(const Pose& estimate, const Pose& truth, const LocalizeRunOptions& options) {
  return (for_truth(estimate, options).translation() - truth.translation()).norm();
}

void write_frames_csv(const std::filesystem::path& file, const Localizer& localizer, const std::vector<Pose>* truth,
                      const LocalizeRunOptions& options) {
  AtomicFile out_file(file);
  std::ostream& out = out_file.stream();
  out << "frame,time,status,fitted,since_fix_m,inlier_fraction,mean_residual_m,submap_keyframes,x,y,z,yaw_deg,event";
  if (truth) out << ",error_m";
  out << '\n';
  for (const LocalizedFrame& f : localizer.frames()) {
    const bool placed = f.status != LocalizationStatus::kUnplaced;
    const Eigen::Vector3d p = f.pose.translation();
    const Eigen::Matrix3d R = f.pose.rotation();
    out << fmt::format("{},{:.6f},{},{:d},{},{},{},{},", f.frame, f.timestamp, localization_status_name(f.status), f.fitted,
                       placed ? fmt::format("{:.2f}", f.since_fix) : std::string(), number_or_empty(f.inlier_fraction, 4),
                       number_or_empty(f.mean_residual, 4), f.submap_keyframes);
    if (placed) {
      out << fmt::format("{:.4f},{:.4f},{:.4f},{:.2f}", p.x(), p.y(), p.z(), std::atan2(R(1, 0), R(0, 0)) * 180.0 / M_PI);
    } else {
      out << ",,,";
    }
    out << ",\"" << f.event << '"';
    if (truth) {
      out << ',' << (placed ? fmt::format("{:.4f}", truth_error(f.pose, (*truth)[f.frame], options)) : std::string());
    }
    out << '\n';
  }
  out_file.commit();
}

/// A relocalisation is true when its pose, brought to the truth's frame (for_truth), agrees with the truth as loops do.
bool is_true(const Pose& estimate, const Pose& truth, const LocalizeRunOptions& options) {
  return agrees_with_truth(for_truth(estimate, options), truth);
}

void write_relocalizations_csv(const std::filesystem::path& file, const Localizer& localizer,
                               const std::vector<Pose>* truth, const LocalizeRunOptions& options) {
  AtomicFile out_file(file);
  std::ostream& out = out_file.stream();
  out << "frame,travelled_m,map_keyframe,score,descriptor_yaw_deg,guess,features,inliers,inlier_fraction,mean_residual_m,"
         "translation_eigenvalue,runner_up_inlier_ratio,accepted,reason,outcome,x,y,z";
  if (truth) out << ",error_m,correct";
  out << '\n';
  for (const RelocalizationRecord& r : localizer.relocalizations()) {
    const auto& v = r.verification;
    out << fmt::format("{},{:.2f},{},{},{},{},{},{},{:.4f},{:.4f},{:.4f},{:.4f},{:d},\"{}\",{},{:.3f},{:.3f},{:.3f}", r.frame,
                       r.travelled, r.keyframe ? std::to_string(*r.keyframe) : std::string(),
                       r.keyframe ? fmt::format("{:.4f}", r.score.score) : std::string(),
                       r.score.yaw ? fmt::format("{:.1f}", *r.score.yaw * 180.0 / M_PI) : std::string(), v.guess,
                       v.features, v.registration.inliers, v.inlier_fraction, v.mean_residual, v.translation_eigenvalue,
                       v.runner_up_inlier_ratio, v.accepted, v.reason, r.outcome, r.pose.translation().x(), r.pose.translation().y(),
                       r.pose.translation().z());
    if (truth) {
      const Pose& t = (*truth)[r.frame];
      out << fmt::format(",{:.3f},{:d}", truth_error(r.pose, t, options), is_true(r.pose, t, options));
    }
    out << '\n';
  }
  out_file.commit();
}

}  // namespace

namespace {

// The frame loop: every frame of `source` through the localiser, the placed
// frames' poses written as they come; returns the loop's wall time [s].
double localize_frames(FrameSource& source, Localizer& localizer, TrajectoryWriter& writer,
                       const LocalizeRunOptions& options) {
  const SourceInfo& info = source.info();
  ProgressBar progress(info.size(), "localize", options.show_progress && !info.live);
  const StageTimer timer;
  for (std::size_t i = 0; !stop_requested(); ++i) {
    const std::optional<SourceFrame> frame = source.next_frame(i);
    if (!frame) break;
    const LocalizedFrame& f = localizer.process(frame->cloud, frame->time);
    if (f.status != LocalizationStatus::kUnplaced) writer.write(f.timestamp, f.pose);
    if (f.status != LocalizationStatus::kUnplaced && options.follow) {
      options.follow(FinishedFrame{
          .index = i, .time = f.timestamp, .scan = frame->cloud, .pose = f.pose, .corrected = nullptr, .loops = {}});
    }
    progress.set_status(fmt::format("{}, {:.0f} ms", localization_status_name(f.status), f.timing.total_ms()));
    progress.advance();
  }
  progress.finish();
  end_live_stream(info);
  return timer.elapsed_s();
}

// [m] the map's own error at `position` (map frame): that of the nearest
// keyframe in the map frame (a session not linked has none).
double map_error_at(const PriorMap& map, const MapError& error, const Eigen::Vector3d& position) {
  double nearest_error = NAN;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < map.size(); ++k) {
    const double d = (map.pose(k).translation() - position).squaredNorm();
    if (std::isfinite(error.keyframe_errors[k]) && d < best) best = d, nearest_error = error.keyframe_errors[k];
  }
  return nearest_error;
}

// Counts of the frames and relocalisations, and their errors against the
// source's reference poses (`truth`: the same in the map's frame) when known.
void evaluate_frames(const Localizer& localizer, const PriorMap& map, const std::optional<std::vector<Pose>>& reference,
                     const std::optional<std::vector<Pose>>& truth, const LocalizeRunOptions& options,
                     LocalizeRunResult& result) {
  const auto& frames = localizer.frames();
  result.frames = frames.size();
  std::vector<Pose> placed_estimates, placed_references;
  std::vector<double> placed_errors, localized_errors, map_errors;
  for (const LocalizedFrame& f : frames) {
    switch (f.status) {
      case LocalizationStatus::kLocalized: ++result.localized; break;
      case LocalizationStatus::kOdometry: ++result.odometry; break;
      case LocalizationStatus::kUnplaced: ++result.unplaced; break;
    }
    if (f.event == "left the mapped area") ++result.left_map;
    if (f.event == "re-entered the mapped area") ++result.reentered;
    if (f.status != LocalizationStatus::kUnplaced && !result.first_placed_frame) result.first_placed_frame = f.frame;
    if (f.status == LocalizationStatus::kUnplaced) continue;
    if (reference) {
      placed_estimates.push_back(f.pose);
      placed_references.push_back((*reference)[f.frame]);
    }
    if (truth) {
      const double e = truth_error(f.pose, (*truth)[f.frame], options);
      placed_errors.push_back(e);
      if (f.status == LocalizationStatus::kLocalized) {
        localized_errors.push_back(e);
        if (options.map_error) map_errors.push_back(map_error_at(map, *options.map_error, f.pose.translation()));
      }
    }
  }
  result.first_placed_m = localizer.first_placed_at();
  for (const auto& r : localizer.relocalizations()) {
    if (r.outcome == "hypothesis") ++result.hypotheses;
    if (r.outcome == "refuted") ++result.refuted;
    if (r.outcome == "confirmed") ++result.confirmed;
  }
  if (truth) {
    std::size_t false_count = 0;
    for (const auto& r : localizer.relocalizations())
      if (r.outcome == "confirmed" && !is_true(r.pose, (*truth)[r.frame], options)) ++false_count;
    result.false_relocalizations = false_count;
    if (!placed_errors.empty()) result.placed_rmse_m = error_stats(placed_errors).rmse;
    if (!localized_errors.empty()) {
      const ErrorStats s = error_stats(localized_errors);
      result.localized_rmse_m = s.rmse;
      result.localized_max_m = s.max;
    }
    if (!map_errors.empty()) result.map_error_where_localized_m = error_stats(map_errors).rmse;
  }
  if (placed_estimates.size() >= 3) {
    result.aligned_ate_m = compute_ate(placed_references, placed_estimates, Alignment::kSE3).aligned.rmse;
  }
}

// timing.json: per-stage timings, Hz, memory and the map's feature cache.
nlohmann::json localize_timing_json(const std::vector<LocalizedFrame>& frames, const std::vector<double>& total,
                                    const Summary& frame_summary, const LocalizeRunResult& result,
                                    const PriorMap& map) {
  const auto column_of = [&](double LocalizeFrameTimings::*member) {
    std::vector<double> v;
    for (const auto& f : frames) v.push_back(f.timing.*member);
    return v;
  };
  nlohmann::json timing{{"frames", frames.size()},
                        {"wall_s", result.seconds},
                        {"hz_median", hz(frame_summary.median)},
                        {"hz_mean", hz(frame_summary.mean)},
                        {"peak_rss_mib", result.peak_rss_mib},
                        {"map_feature_loads", map.loads()},
                        {"map_keyframes_cached", map.cached()},
                        {"map_cache_mib", static_cast<double>(map.cached_bytes()) / (1024.0 * 1024.0)},
                        {"stages",
                         {{"odometry", stage_stats(column_of(&LocalizeFrameTimings::odometry_ms))},
                          {"relocalization", stage_stats(column_of(&LocalizeFrameTimings::relocalization_ms))},
                          {"tracking", stage_stats(column_of(&LocalizeFrameTimings::tracking_ms))},
                          {"total", stage_stats(total)}}}};
  return timing;
}

nlohmann::json localize_summary_json(const SourceInfo& info, const PriorMap& map, const LocalizeRunResult& result) {
  nlohmann::json summary{{"command", "localize"},
                         {"first_frame", info.first_frame},
                         {"map", std::filesystem::absolute(map.saved().folder).lexically_normal().string()},
                         {"map_keyframes", map.size()},
                         {"frames", result.frames},
                         {"localized", result.localized},
                         {"odometry", result.odometry},
                         {"unplaced", result.unplaced},
                         {"relocalization_hypotheses", result.hypotheses},
                         {"relocalizations_confirmed", result.confirmed},
                         {"relocalizations_refuted", result.refuted},
                         {"left_mapped_area", result.left_map},
                         {"reentered_mapped_area", result.reentered}};
  if (result.first_placed_m) summary["first_placed_after_m"] = *result.first_placed_m;
  if (result.first_placed_frame) summary["first_placed_frame"] = *result.first_placed_frame;
  if (result.aligned_ate_m) summary["placed_ate_se3_m"] = *result.aligned_ate_m;
  if (result.false_relocalizations) summary["false_relocalizations"] = *result.false_relocalizations;
  if (result.localized_rmse_m) summary["localized_rmse_in_map_m"] = *result.localized_rmse_m;
  if (result.map_error_where_localized_m) summary["map_error_where_localized_m"] = *result.map_error_where_localized_m;
  if (result.placed_rmse_m) summary["placed_rmse_in_map_m"] = *result.placed_rmse_m;
  if (info.folder) summary["sequence"] = std::filesystem::absolute(*info.folder).lexically_normal().string();
  return summary;
}

}  // namespace

std::optional<MapError> map_error_against_source(const PriorMap& map) {
  try {
    std::vector<std::vector<Pose>> truth;
    for (const MapSession& session : map_sessions(map.saved())) truth.push_back(read_sequence_truth(session.source));
    KeyframeAlignment alignment = align_keyframes(map.saved(), truth);
    return MapError{alignment.alignment, std::move(alignment.aligned)};
  } catch (const InputError&) {
    return std::nullopt;
  } catch (const std::invalid_argument&) {
    return std::nullopt;
  }
}

LocalizeRunResult run_localize(FrameSource& source, const SaloamConfig& config, const PriorMap& map,
                               std::optional<SgprNetwork> network, const std::filesystem::path& out_dir,
                               const LocalizeRunOptions& options) {
  const SourceInfo& info = source.info();
  if (config.odometry.use_semantics && !info.has_labels) warn_no_labels(info);
  OutputFolder folder = open_run_folder(out_dir, info.folder, "localize", kLocalizeOutputs);
  const std::optional<Pose> tr = output_velo_to_cam(info);
  TrajectoryWriter writer(folder / "poses.txt", folder / "poses_tum.txt", tr, info.live);

  Localizer localizer(with_source_up(config, info), map, std::move(network));
  LocalizeRunResult result;
  result.seconds = localize_frames(source, localizer, writer, options);
  result.interrupted = stop_requested();
  writer.commit();

  // Counts and the evaluation.
  const auto& frames = localizer.frames();
  const std::optional<std::vector<Pose>> reference = reference_lidar_poses(info, frames.size());
  std::optional<std::vector<Pose>> truth;
  if (reference && options.truth_map_from_source) {
    truth.emplace();
    for (const Pose& p : *reference) truth->push_back(orthonormalized(*options.truth_map_from_source * p));
  }
  evaluate_frames(localizer, map, reference, truth, options, result);
  std::vector<double> total;
  for (const auto& f : frames) total.push_back(f.timing.total_ms());
  const Summary frame_summary = summarize(total);
  result.median_frame_ms = frame_summary.median;
  result.mean_frame_ms = frame_summary.mean;
  result.peak_rss_mib = peak_rss_mib();
  result.map_loads = map.loads();

  const std::vector<Pose>* truth_ptr = truth ? &*truth : nullptr;
  write_frames_csv(folder / "frames.csv", localizer, truth_ptr, options);
  write_relocalizations_csv(folder / "relocalizations.csv", localizer, truth_ptr, options);
  write_file_atomically(folder / "timing.json",
                        localize_timing_json(frames, total, frame_summary, result, map).dump(2) + '\n');
  nlohmann::json summary = localize_summary_json(info, map, result);
  report_stream(source, summary);
  write_run_summary(folder, summary);
  result.interrupted = stop_requested();
  result.files = folder.files();
  return result;
}

}  // namespace saloam
