#include "saloam/runs/slam_run.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/eval/evaluation_report.hpp"
#include "saloam/io/ply.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/maps/session_join.hpp"
#include "saloam/maps/session_report.hpp"
#include "saloam/maps/slam_map.hpp"
#include "saloam/mapping/map_render.hpp"
#include "saloam/place/graph_json.hpp"
#include "saloam/runs/map_building.hpp"
#include "saloam/runs/odometry_run.hpp"
#include "saloam/runs/output_folder.hpp"
#include "saloam/runs/stream_report.hpp"
#include "saloam/runs/timing_report.hpp"
#include "saloam/runs/trajectory_writer.hpp"
#include "saloam/viz/canvas.hpp"

namespace saloam {

namespace {

std::string pose_numbers(const Pose& T) {
  double v[12];
  pose_to_3x4(T, v);
  return fmt::format("{:.6f}", fmt::join(v, v + 12, " "));
}

// Why a loop was verified: its score (from the sensor, or from the query
// described to the left or right, loop.lateral_query_offset) or its
// estimated distance.
const char* proposed_by(const LoopRecord& loop) {
  if (loop.by_proximity) return "proximity";
  if (loop.query_offset > 0) return "score_left";
  return loop.query_offset < 0 ? "score_right" : "score";
}

void write_loops_csv(const std::filesystem::path& file, const SlamSystem& slam, const std::vector<Pose>* gt) {
  AtomicFile out_file(file);
  std::ostream& out = out_file.stream();
  out << "query_frame,match_frame,query_keyframe,match_keyframe,travelled_m,score,sgpr_score,scancontext_score,"
         "descriptor_yaw_deg,proposed_by,guess,features,correspondences,inliers,inlier_fraction,mean_residual_m,loss_r,"
         "translation_eigenvalue,runner_up_inlier_ratio,converged,passes_loss_test,passes_normalized_test,accepted,reason,"
         "relative_pose_3x4";
  if (gt) out << ",gt_distance_m,gt_yaw_deg,translation_error_m,horizontal_error_m,rotation_error_deg,correct";
  out << '\n';
  for (const auto& loop : slam.loops()) {
    const auto& v = loop.verification;
    const auto& r = v.registration;
    out << fmt::format("{},{},{},{},{:.2f},{:.6f},{:.6f},{:.6f},{},{},{},{},{},{},{:.4f},{:.4f},{:.2f},{:.4f},{:.3f},{:d},{:d},{:d},{:d},\"{}\",{}",
                       loop.query_frame, loop.match_frame, loop.query_keyframe, loop.match_keyframe, loop.travelled,
                       loop.score.score, loop.score.sgpr_score, loop.score.scancontext_score,
                       loop.score.yaw ? fmt::format("{:.1f}", *loop.score.yaw * 180.0 / M_PI) : std::string(),
                       proposed_by(loop), v.guess, v.features, r.correspondences(), r.inliers, v.inlier_fraction, v.mean_residual,
                       r.loss, v.translation_eigenvalue, v.runner_up_inlier_ratio, r.converged, v.passes_loss_test, v.passes_normalized_test,
                       v.accepted, v.reason, pose_numbers(v.relative));
    if (gt) {
      const LoopTruth t = loop_truth(loop, *gt);
      out << fmt::format(",{:.3f},{:.1f},{:.3f},{:.3f},{:.3f},{:d}", t.gt_distance, t.gt_yaw_deg, t.translation_error,
                         t.horizontal_error, t.rotation_error_deg, t.correct);
    }
    out << '\n';
  }
  out_file.commit();
}

void write_graph_map(const std::filesystem::path& file, const SlamSystem& slam) {
  nlohmann::json keyframes = nlohmann::json::array();
  for (std::size_t k = 0; k < slam.keyframes().size(); ++k) {
    const Keyframe& kf = slam.keyframes()[k];
    nlohmann::json j = graph_to_json(kf.place.graph);
    double pose[12];
    pose_to_3x4(slam.keyframe_pose(k), pose);
    j["frame"] = kf.frame;
    j["pose"] = std::vector<double>(pose, pose + 12);
    keyframes.push_back(std::move(j));
  }
  write_file_atomically(file, nlohmann::json{{"frame", "LiDAR, world = first frame"}, {"keyframes", keyframes}}.dump() + '\n');
}

void write_timing(const std::filesystem::path& file, const SlamSystem& slam, double seconds, double rss_mib,
                  const std::vector<SourceStageTimes>& source_stages) {
  const auto& t = slam.timings();
  const std::vector<double> total = column(t, &SlamFrameTimings::total_ms);
  const Summary frame = summarize(total);
  nlohmann::json j{
      {"frames", total.size()},
      {"keyframes", slam.keyframes().size()},
      {"optimizations", slam.optimizations()},
      {"wall_s", seconds},
      {"hz_median", hz(frame.median)},
      {"hz_mean", hz(frame.mean)},
      {"peak_rss_mib", rss_mib},
      {"keyframe_store_mib", static_cast<double>(slam.keyframe_bytes()) / (1024.0 * 1024.0)},
      {"stages",
       {{"odometry", stage_stats(column(t, &SlamFrameTimings::odometry_ms))},
        {"place_descriptor", stage_stats(column(t, &SlamFrameTimings::place_ms))},
        {"candidates_and_scoring", stage_stats(column(t, &SlamFrameTimings::search_ms))},
        {"verification", stage_stats(column(t, &SlamFrameTimings::verification_ms))},
        {"pose_graph", stage_stats(column(t, &SlamFrameTimings::optimization_ms))},
        {"loop_closure_total", stage_stats(column(t, &SlamFrameTimings::loop_ms))},
        {"total", stage_stats(total)}}}};
  for (const auto& stage : source_stages)
    j["source_stages"][stage.name] = {{"wall", stage_stats(column(stage.per_frame, &StageTime::wall_ms))},
                                      {"cpu", stage_stats(column(stage.per_frame, &StageTime::cpu_ms))}};
  write_file_atomically(file, j.dump(2) + '\n');
}

std::vector<Eigen::Vector2d> top_down(const std::vector<Pose>& poses, std::pair<int, int> axes) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(poses.size());
  for (const auto& p : poses) points.emplace_back(p.translation()[axes.first], p.translation()[axes.second]);
  return points;
}

void plot_trajectories(const std::filesystem::path& file, const std::vector<Pose>& odometry,
                       const std::vector<Pose>& slam, const std::vector<Pose>* gt, std::size_t loops) {
  const auto axes = top_down_axes(gt ? *gt : slam);
  Plot plot(1000, 900);
  std::vector<Eigen::Vector2d> all = top_down(odometry, axes);
  const auto slam_points = top_down(slam, axes);
  all.insert(all.end(), slam_points.begin(), slam_points.end());
  if (gt) {
    const auto g = top_down(*gt, axes);
    all.insert(all.end(), g.begin(), g.end());
  }
  plot.fit_range(all, true);
  plot.set_title(fmt::format("trajectories ({} loops accepted)", loops));
  plot.set_labels("x [m]", axes.second == 2 ? "z [m]" : "y [m]");
  std::vector<LegendEntry> legend;
  if (gt) {
    plot.line(top_down(*gt, axes), Rgb{120, 120, 120}, 3.0);
    legend.push_back({"ground truth", Rgb{120, 120, 120}});
  }
  plot.line(top_down(odometry, axes), Rgb{214, 39, 40}, 1.5, true);
  legend.push_back({"odometry", Rgb{214, 39, 40}});
  plot.line(slam_points, Rgb{31, 119, 180}, 1.8);
  legend.push_back({"loop closed", Rgb{31, 119, 180}});
  plot.legend(legend);
  plot.save_png(file);
}

}  // namespace

std::optional<SgprNetwork> load_loop_network(const SaloamConfig& config) {
  if (!uses_sgpr(parse_place_detector(config.loop.detector))) return std::nullopt;
  if (config.loop.sgpr_model.empty()) {
    throw ConfigError(fmt::format("loop.detector '{}' needs SGPR weights: give --set loop.sgpr_model=FILE.sgw",
                                  config.loop.detector));
  }
  return SgprNetwork::load(config.loop.sgpr_model);
}

namespace {

struct RunTruth {
  std::optional<std::vector<Pose>> camera;        ///< poses.txt of the processed frames (output convention)
  std::optional<std::vector<Pose>> lidar;         ///< the same in the LiDAR frame
  std::optional<std::vector<Pose>> sensor_lidar;  ///< where the scans were really taken, when that differs
  [[nodiscard]] const std::vector<Pose>* loop_reference() const {
    return sensor_lidar ? &*sensor_lidar : lidar ? &*lidar : nullptr;
  }
};

// Ground truth of the processed frames, camera frame (trajectories) and
// LiDAR frame (loops). A simulated sequence whose given heights did not fit
// its ground has sensor poses (poses_sensor.txt), where the scans were really
// taken: loops are judged against them (poses.txt is wrong in height there,
// as KITTI's).
RunTruth run_truth(const SourceInfo& source, const std::optional<Pose>& tr, std::size_t frames) {
  RunTruth truth;
  const auto& camera = source.camera_poses;
  if (!camera || frames == 0) return truth;
  const auto slice_of = [&](const std::vector<Pose>& all) {
    std::vector<Pose> slice(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(frames));
    const Pose rebase = slice.front().inverse();  // world = first processed frame, as the estimates
    for (auto& p : slice) p = orthonormalized(rebase * p);
    return slice;
  };
  const auto to_lidar = [&](const std::vector<Pose>& in_camera) {
    std::vector<Pose> lidar;
    for (const auto& p : in_camera) lidar.push_back(orthonormalized(tr->inverse() * p * *tr));
    return lidar;
  };
  truth.camera = slice_of(*camera);
  if (!tr) return truth;
  truth.lidar = to_lidar(*truth.camera);
  if (const auto& sensor = source.sensor_camera_poses) truth.sensor_lidar = to_lidar(slice_of(*sensor));
  return truth;
}

nlohmann::json loop_summary_json(const LoopSummary& s) {
  return {{"accepted_true", s.accepted_true},
          {"accepted_false", s.accepted_false},
          {"accepted_reverse", s.accepted_reverse},
          {"rejected_but_correct", s.rejected_true},
          {"revisit_keyframes", s.revisit_keyframes},
          {"revisit_stretches", s.revisit_stretches},
          {"missed_stretches", s.missed_stretches},
          {"reverse_stretches", s.reverse_stretches},
          {"missed_reverse_stretches", s.missed_reverse_stretches}};
}

// Evaluates both trajectories and the loops against the ground truth (when
// known), writes eval_{odometry,slam}.{json,png} and returns the run's
// summary, with where the frames came from for `saloam view` and `saloam
// eval` (the source's folder and first frame).
nlohmann::json evaluate_run(const SlamSystem& slam, const SaloamConfig& config, const RunTruth& truth,
                  const std::vector<Pose>& odometry_out, const std::vector<Pose>& slam_out,
                  const std::filesystem::path& out_dir, SlamRunResult& result, const SourceInfo& origin) {
  nlohmann::json summary{{"command", "slam"},
                         {"first_frame", origin.first_frame},
                         {"frames", result.frames},
                         {"keyframes", result.keyframes},
                         {"detector", config.loop.detector},
                         {"loops_verified", result.loops_verified},
                         {"loops_accepted", result.loops_accepted},
                         {"registration_failures", result.registration_failures},
                         {"degenerate_frames", result.degenerate_frames},
                         {"gravity", gravity_json(result.gravity)}};
  if (truth.camera && result.frames >= 2) {
    result.odometry_evaluation = evaluate_trajectories(*truth.camera, odometry_out);
    result.slam_evaluation = evaluate_trajectories(*truth.camera, slam_out);
    const EvaluationLabels odometry_labels{"ground truth", "poses_odometry.txt"};
    const EvaluationLabels slam_labels{"ground truth", "poses.txt"};
    write_evaluation_json(out_dir / "eval_odometry.json", *result.odometry_evaluation, odometry_labels);
    write_evaluation_json(out_dir / "eval_slam.json", *result.slam_evaluation, slam_labels);
    plot_evaluation(out_dir / "eval_odometry.png", *truth.camera, odometry_out, *result.odometry_evaluation,
                    odometry_labels);
    plot_evaluation(out_dir / "eval_slam.png", *truth.camera, slam_out, *result.slam_evaluation, slam_labels);
    summary["odometry"] = evaluation_to_json(*result.odometry_evaluation, odometry_labels, false);
    summary["slam"] = evaluation_to_json(*result.slam_evaluation, slam_labels, false);
  }
  if (const std::vector<Pose>* reference = truth.loop_reference()) {
    const LoopTruthOptions truth_options = LoopTruthOptions::from_config(config.loop);
    result.loop_summary = summarize_loops(slam, *reference, truth_options);
    result.loop_reference = truth.sensor_lidar ? "poses_sensor.txt" : "poses.txt";
    if (truth.sensor_lidar) result.loop_summary_poses_txt = summarize_loops(slam, *truth.lidar, truth_options);
    summary["loops_judged_against"] = result.loop_reference;
    if (result.loop_summary_poses_txt) {
      summary["loops_vs_poses_txt"] = {{"accepted_true", result.loop_summary_poses_txt->accepted_true},
                                       {"accepted_false", result.loop_summary_poses_txt->accepted_false}};
    }
    summary["loops"] = loop_summary_json(*result.loop_summary);
  }
  if (origin.folder) put_summary_path(summary, "sequence", std::filesystem::absolute(*origin.folder).lexically_normal());
  return summary;
}

void write_map_outputs(const SlamSystem& slam, const LabelledCloud& map, const std::vector<Pose>& optimized,
                       const std::filesystem::path& out_dir) {
  write_ply(out_dir / "map.ply", map);
  std::vector<WorldSegment> links;
  for (const auto& loop : slam.loops()) {
    if (!loop.verification.accepted) continue;
    links.emplace_back(optimized[loop.match_frame].translation(), optimized[loop.query_frame].translation());
  }
  render_top_down(out_dir / "map.png", map, optimized, {}, links);
}

SlamRunResult summarize_run(const SlamSystem& slam, double seconds) {
  SlamRunResult result;
  result.seconds = seconds;
  result.interrupted = stop_requested();
  result.frames = slam.odometry_poses().size();
  result.keyframes = slam.keyframes().size();
  result.loops_accepted = slam.accepted_loops();
  result.loops_verified = slam.loops().size();
  result.peak_rss_mib = peak_rss_mib();
  result.gravity = slam.odometry().gravity();
  result.median_frame_ms = summarize(column(slam.timings(), &SlamFrameTimings::total_ms)).median;
  result.mean_loop_ms = summarize(column(slam.timings(), &SlamFrameTimings::loop_ms)).mean;
  return result;
}

}  // namespace

namespace {

// Tells the run's follower about frame `i` once the SLAM has processed it:
// its loop-closed pose, every pose when loop closure moved them (the pose
// graph was optimised since `optimizations_before`), the loops accepted
// since `loops_before`.
void tell_follower(const FrameFollower& follow, const SlamSystem& slam, std::size_t i, const LabelledCloud& scan,
                   double time, std::size_t loops_before, std::size_t optimizations_before) {
  std::vector<std::pair<std::size_t, std::size_t>> accepted;
  for (std::size_t l = loops_before; l < slam.loops().size(); ++l) {
    const LoopRecord& loop = slam.loops()[l];
    if (loop.verification.accepted) accepted.emplace_back(loop.query_frame, loop.match_frame);
  }
  std::optional<std::vector<Pose>> corrected;
  if (slam.optimizations() != optimizations_before) corrected = slam.optimized_poses();
  follow(FinishedFrame{.index = i,
                       .time = time,
                       .scan = scan,
                       .pose = corrected ? corrected->back() : slam.optimized_pose(i),
                       .corrected = corrected ? &*corrected : nullptr,
                       .loops = accepted});
}

// The frame loop: every frame of `source` through the SLAM, the odometry's
// poses written as they come, and a stream's scans kept for the map.
double process_frames(FrameSource& source, SlamSystem& slam, TrajectoryWriter& odometry_writer,
                      std::optional<MapScanStore>& map_scans, const SlamRunOptions& options,
                      RegistrationHealth& health) {
  const SourceInfo& info = source.info();
  ProgressBar progress(info.size(), "slam", options.show_progress && !info.live);
  const StageTimer timer;
  for (std::size_t i = 0; !stop_requested(); ++i) {
    std::optional<SourceFrame> frame = source.next_frame(i);
    if (!frame) break;
    const LabelledCloud& scan = frame->cloud;
    const double t = frame->time;
    const std::size_t loops_before = slam.loops().size(), optimizations_before = slam.optimizations();
    odometry_writer.write(t, slam.process(scan, t));
    health.note(slam.odometry(), info.first_frame + i);
    if (options.follow) tell_follower(options.follow, slam, i, scan, t, loops_before, optimizations_before);
    if (map_scans) map_scans->offer(i, scan);
    progress.set_status(fmt::format("{} loops, {:.0f} ms", slam.accepted_loops(), slam.timings().back().total_ms()));
    progress.advance();
  }
  progress.finish();
  end_live_stream(info);
  return timer.elapsed_s();
}

// Everything written after the frame loop: loop-closed poses, timing, loops,
// graph map, trajectories and their evaluation; returns the run's summary.
nlohmann::json write_results(const SlamSystem& slam, const std::vector<Pose>& optimized, TrajectoryWriter& slam_writer,
                             const SaloamConfig& config, const FrameSource& source, const std::optional<Pose>& tr,
                             const std::filesystem::path& out_dir, SlamRunResult& result) {
  const SourceInfo& info = source.info();
  for (std::size_t i = 0; i < optimized.size(); ++i) slam_writer.write(slam.timestamps().at(i), optimized[i]);
  slam_writer.commit();
  write_timing(out_dir / "timing.json", slam, result.seconds, result.peak_rss_mib, source.stage_times());
  const RunTruth truth = run_truth(info, tr, result.frames);
  write_loops_csv(out_dir / "loops.csv", slam, truth.loop_reference());
  if (uses_sgpr(parse_place_detector(config.loop.detector))) write_graph_map(out_dir / "graph_map.json", slam);
  const std::vector<Pose> odometry_out = output_poses(slam.odometry_poses(), tr);
  const std::vector<Pose> slam_out = output_poses(optimized, tr);
  plot_trajectories(out_dir / "trajectories.png", odometry_out, slam_out, truth.camera ? &*truth.camera : nullptr,
                    slam.accepted_loops());
  return evaluate_run(slam, config, truth, odometry_out, slam_out, out_dir, result, info);
}

// The run's keyframes joined to a saved map, and every frame's pose in the
// map's frame when linked (in the run's own otherwise).
struct JoinedSession {
  std::unique_ptr<PriorMap> joining;
  JoinedMaps joined;
  std::vector<Pose> frame_poses;
};

JoinedSession join_session(const SlamSystem& slam, const SaloamConfig& config, const MapManifest& manifest,
                           const PriorMap& map) {
  JoinedSession s;
  const auto cached = static_cast<std::size_t>(std::max(1, config.localize.cached_keyframes));
  s.joining = std::make_unique<PriorMap>(saved_map_of(slam, config, manifest),
                                         [&slam](std::size_t k) { return slam.keyframes()[k].features; }, cached);
  const PlaceRecognizer places = PlaceRecognizer::from_config(config.loop, load_loop_network(config));
  s.joined = join_maps(map, *s.joining, config, places);
  std::vector<Pose> keyframe_poses;
  for (std::size_t k = 0; k < slam.keyframes().size(); ++k) {
    keyframe_poses.push_back(s.joined.map.keyframes[s.joined.base_keyframes + k].pose);
  }
  s.frame_poses = slam.optimized_poses(keyframe_poses);
  spdlog::info("{}", describe_join(s.joined, map.saved().folder.string()));
  return s;
}

// What a saved map records of the run's source: sensor, folder, first frame
// and the camera frame of its outputs.
MapManifest run_manifest(const SourceInfo& info, const std::optional<Pose>& tr, const std::string& sensor) {
  MapManifest manifest;
  manifest.sensor = sensor;
  if (info.folder) manifest.source = std::filesystem::absolute(*info.folder).lexically_normal().string();
  manifest.first_frame = info.first_frame;
  manifest.camera_frame_outputs = tr.has_value();
  if (tr) manifest.velo_to_cam = *tr;
  return manifest;
}

// Saves the run's map (joined to `join_map` when `joined`) into `folder`;
// notes its size and time in `result` and returns them for the summary.
nlohmann::json save_run_map(const std::filesystem::path& folder, const SlamSystem& slam, const SaloamConfig& config,
                            const MapManifest& manifest, const JoinedSession* joined, const PriorMap* join_map,
                            SlamRunResult& result) {
  const StageTimer save_timer;
  if (joined) {
    write_joined_map(folder, joined->joined, *join_map, *joined->joining);
  } else {
    write_slam_map(folder, slam, config, manifest);
  }
  result.map_save_seconds = save_timer.elapsed_s();
  result.map_bytes = map_disk_bytes(folder);
  result.map_keyframes = joined ? joined->joined.map.keyframes.size() : slam.keyframes().size();
  return {{"folder", std::filesystem::absolute(folder).lexically_normal().string()},
          {"bytes", *result.map_bytes},
          {"keyframes", result.map_keyframes},
          {"seconds", result.map_save_seconds}};
}

}  // namespace

SlamRunResult run_slam(FrameSource& source, const SaloamConfig& config, std::optional<SgprNetwork> network,
                       const std::filesystem::path& out_dir, const SlamRunOptions& options) {
  OutputFolder folder = open_slam_folder(out_dir, source.info());
  return run_slam(source, config, std::move(network), folder, options);
}

OutputFolder open_slam_folder(const std::filesystem::path& out_dir, const SourceInfo& source) {
  return open_run_folder(out_dir, source.folder, "slam", kSlamOutputs);
}

SlamRunResult run_slam(FrameSource& source, const SaloamConfig& config, std::optional<SgprNetwork> network,
                       OutputFolder& folder, const SlamRunOptions& options) {
  const SourceInfo& info = source.info();
  if (config.odometry.use_semantics && !info.has_labels) warn_no_labels(info);
  const std::optional<Pose> tr = output_velo_to_cam(info);
  const std::filesystem::path& out_dir = folder.path();
  if (options.save_map) check_map_destination(*options.save_map);

  // A stream cannot be read again for the map: keep what the map needs as it goes by.
  const SemanticMapOptions map_options = SemanticMapOptions::from_config(config.slam);
  const auto map_step = static_cast<std::size_t>(std::max(1, config.slam.map_frame_step));
  std::optional<MapScanStore> map_scans;
  if (options.write_map && !info.rereadable) map_scans.emplace(map_options, map_step);

  SlamSystem slam(with_source_up(config, info), std::move(network));
  // A live run's odometry poses grow in place, for a process that follows them.
  TrajectoryWriter odometry_writer(out_dir / "poses_odometry.txt", out_dir / "poses_odometry_tum.txt", tr, info.live);
  TrajectoryWriter slam_writer(out_dir / "poses.txt", out_dir / "poses_tum.txt", tr);
  RegistrationHealth health;
  SlamRunResult result = summarize_run(slam, process_frames(source, slam, odometry_writer, map_scans, options, health));
  result.registration_failures = health.failures();
  result.degenerate_frames = health.degenerate_frames();
  odometry_writer.commit();
  const MapManifest manifest = run_manifest(info, tr, options.sensor);
  std::optional<JoinedSession> joined;
  if (options.join_map && !stop_requested() && !slam.keyframes().empty()) {
    joined.emplace(join_session(slam, config, manifest, *options.join_map));
    write_cross_session_csv(out_dir / "cross_session.csv", joined->joined);
    result.join = describe_join(joined->joined, options.join_map->saved().folder.string());
  }
  const std::vector<Pose> optimized = joined ? joined->frame_poses : slam.optimized_poses();
  nlohmann::json summary = write_results(slam, optimized, slam_writer, config, source, tr, out_dir, result);
  if (joined) summary["session_join"] = join_summary_json(joined->joined);
  if (options.save_map && !stop_requested() && !slam.keyframes().empty()) {
    summary["saved_map"] = save_run_map(*options.save_map, slam, config, manifest, joined ? &*joined : nullptr,
                                        options.join_map, result);
  }
  if (options.write_map && !stop_requested()) {
    const LabelledCloud map = map_scans ? map_scans->build(optimized, options.show_progress)
                                        : build_semantic_map(source, optimized, map_options, map_step,
                                                             options.show_progress);
    if (!stop_requested()) write_map_outputs(slam, map, optimized, out_dir);
  }
  report_stream(source, summary);
  write_run_summary(folder, std::move(summary));
  result.interrupted = stop_requested();
  result.files = folder.files();
  return result;
}

}  // namespace saloam
