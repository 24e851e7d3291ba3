// `saloam demo`: the whole system end to end on data it makes itself.
// Simulates a labelled sequence (default: the ~1.6 km figure eight, which
// revisits places in the same and in the opposite direction; HDL-64E,
// emulated segmentation-network labels) and streams it, scan by scan, into
// the SLAM (semantic odometry with loop closure) and the label-agnostic
// odometry baseline: the simulator renders ahead on a worker thread, and the
// scans reach the disk only with --keep-sequence. Evaluates both against the
// ground truth and writes the semantic map and pictures.

#include <cmath>
#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/output_folder.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/eval/evaluation_report.hpp"
#include "saloam/runs/odometry_run.hpp"
#include "saloam/runs/output_folder.hpp"
#include "saloam/runs/slam_run.hpp"
#include "saloam/sim/lidar.hpp"
#include "saloam/sim/simulated_source.hpp"
#include "saloam/sim/simulation_record.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sources/open_source.hpp"
#include "saloam/viewer/viewer_page.hpp"
#include "saloam/viz/range_image.hpp"

namespace saloam::cli {
namespace {

/// The demo's route (it revisits places both ways); the other simulation
/// defaults are SimulationOptions'.
SimulationOptions demo_route() {
  SimulationOptions sim;
  sim.preset = "figure-eight";
  return sim;
}

struct DemoOptions {
  std::string out = "demo_output";
  SimulationOptions sim = demo_route();  ///< --preset, --beams, --seed
  std::string frames;
  bool gt_labels = false;
  bool keep_sequence = false;
  bool reuse = false;
  bool baseline = true;
  SegmentOptions segment;  ///< --segment: the network labels the raw simulated scans
  ConfigOptions config;
};

/// What the demo writes into OUT itself (OUT/slam and OUT/sequence keep records of their own).
const std::vector<std::string> kDemoOutputs{"eval_baseline.json", "eval_baseline.png", "odometry_baseline/poses.txt",
                                            "odometry_baseline/poses_tum.txt"};

void heading(const std::string& text) { std::cout << "\n== " << text << " ==\n" << std::flush; }

SimulationOptions simulation_options(const DemoOptions& options) {
  SimulationOptions sim = options.sim;
  sim.labels = options.gt_labels ? LabelMode::kGroundTruth : LabelMode::kNoisy;
  sim.show_progress = false;
  if (!options.frames.empty()) {
    const auto range = FrameRange::parse(options.frames);
    sim.first_frame = range.first;
    sim.end_frame = range.end;
  }
  return sim;
}

/// The label-agnostic odometry (--no-semantics) run on the same stream as the
/// SLAM, scan by scan, for the comparison in the summary.
OdometryConfig without_semantics(OdometryConfig config) {
  config.use_semantics = false;
  return config;
}

std::uintmax_t disk_usage(const std::filesystem::path& folder) {
  std::uintmax_t bytes = 0;
  std::error_code error;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder, error)) {
    if (entry.is_regular_file(error)) bytes += entry.file_size(error);
  }
  return bytes;
}

void print_summary(const SlamRunResult& slam, const std::optional<TrajectoryEvaluation>& baseline) {
  std::cout << "| trajectory | KITTI t_err [%] | KITTI r_err [deg/100 m] | ATE RMSE [m] | RPE [m/frame] |\n"
               "|---|---|---|---|---|\n";
  auto row = [](const std::string& name, const TrajectoryEvaluation& e) {
    std::cout << fmt::format("| {} | {} | {} | {} | {} |\n", name, format_metric(e.kitti.t_err_percent, 3),
                             format_metric(e.kitti.r_err_deg_per_100m, 3), format_metric(e.ate.aligned.rmse, 3),
                             format_metric(e.rpe.trans_rmse_m, 4));
  };
  if (baseline) row("odometry, label-agnostic baseline", *baseline);
  if (slam.odometry_evaluation) row("odometry, semantic (SA-LOAM)", *slam.odometry_evaluation);
  if (slam.slam_evaluation) row("SLAM: semantic odometry + loop closure", *slam.slam_evaluation);
  if (slam.loop_summary) {
    const LoopSummary& l = *slam.loop_summary;
    std::cout << fmt::format("\nloops: {} accepted ({} true, {} false against the ground truth; {} in reverse), "
                             "{} of {} revisited stretches closed ({} of {} reverse)\n",
                             l.accepted, l.accepted_true, l.accepted_false, l.accepted_reverse,
                             l.revisit_stretches - l.missed_stretches, l.revisit_stretches,
                             l.reverse_stretches - l.missed_reverse_stretches, l.reverse_stretches);
  }
}

/// The 3D view of the run (as `saloam view OUT/slam`), added to the run's
/// summary. A streamed sequence is not on disk: its ground truth comes from
/// the simulation, and the scans the page embeds are rendered again.
void write_view_page(OutputFolder& run_folder, const SimulatedSequence* streamed) {
  const std::filesystem::path& run_dir = run_folder.path();
  ViewerOptions options;
  if (streamed) {
    const Pose tr = streamed->velo_to_cam();
    std::vector<Pose> ground_truth;
    for (const Pose& camera : streamed->camera_poses()) ground_truth.push_back(orthonormalized(tr.inverse() * camera * tr));
    options.ground_truth = std::move(ground_truth);
    options.scans = [streamed](std::size_t frame) { return streamed->render(frame).cloud; };
  }
  try {
    const ViewerPageStats s = write_viewer_page(run_dir, run_dir / "view.html", options);
    update_run_summary(run_folder);
    std::cout << fmt::format("3D view: {} ({:.1f} MB; open it in a browser)\n", (run_dir / "view.html").string(),
                             static_cast<double>(s.bytes) / 1e6);
  } catch (const InputError& e) {
    spdlog::warn("no view.html: {}", e.what());
  }
}

/// The demo's frames: the simulator streaming them (it renders ahead on
/// another thread while the SLAM runs, and writes them to `sequence_dir`
/// only with --keep-sequence), or with --reuse the sequence kept earlier.
struct DemoSource {
  std::unique_ptr<SimulatedSequence> simulated;  ///< none when read from disk
  std::unique_ptr<FrameSource> frames;           ///< declared last: destroyed first (it streams `simulated`)
};

DemoSource open_demo_source(const DemoOptions& options, const SaloamConfig& config,
                            const std::filesystem::path& sequence_dir, bool from_disk) {
  DemoSource source;
  SourceOptions stages;
  stages.segmentation = options.segment.stage(config);
  if (from_disk) {
    source.frames = open_source(sequence_dir, stages);
    return source;
  }
  std::filesystem::remove_all(sequence_dir);
  source.simulated = std::make_unique<SimulatedSequence>(simulation_options(options));
  const auto keep = options.keep_sequence ? std::optional(sequence_dir) : std::nullopt;
  source.frames = add_stages(std::make_unique<SimulatedSource>(*source.simulated, 16, keep), stages);
  return source;
}

/// --reuse reads the sequence an earlier --keep-sequence left, when it is
/// the one these options simulate (its simulation.yaml says how it was made).
void check_kept_sequence(const DemoOptions& options, const std::filesystem::path& sequence_dir) {
  if (!path_taken(sequence_dir / "poses.txt")) {
    throw ConfigError(fmt::format("--reuse: {} holds no kept sequence; run the demo once with --keep-sequence",
                                  sequence_dir.string()));
  }
  const std::vector<std::string> differences = simulation_differences(sequence_dir, simulation_options(options));
  if (!differences.empty()) {
    throw ConfigError(fmt::format("--reuse: the sequence kept in {} was simulated otherwise ({}); give the options it "
                                  "was kept with, or leave out --reuse",
                                  sequence_dir.string(), fmt::join(differences, "; ")));
  }
}

/// eval_baseline.{json,png}: the label-agnostic odometry against the ground truth.
TrajectoryEvaluation evaluate_baseline(const std::filesystem::path& out, const std::vector<Pose>& ground_truth,
                                       const std::vector<Pose>& baseline) {
  const TrajectoryEvaluation evaluation = evaluate_trajectories(ground_truth, baseline);
  const EvaluationLabels labels{"ground truth", "odometry_baseline/poses.txt"};
  write_evaluation_json(out / "eval_baseline.json", evaluation, labels);
  plot_evaluation(out / "eval_baseline.png", ground_truth, baseline, evaluation, labels);
  return evaluation;
}

void print_outputs(const SlamRunResult& slam, double seconds, const std::filesystem::path& out) {
  std::cout << fmt::format("\n{} frames in {:.0f} s; SLAM median {:.1f} Hz, loop closure {:.2f} ms/frame amortised; "
                           "{:.0f} MB written to {}\n",
                           slam.frames, seconds, 1000.0 / std::max(slam.median_frame_ms, 1e-9), slam.mean_loop_ms,
                           static_cast<double>(disk_usage(out)) / 1e6, out.string());
  std::cout << fmt::format("map: {}, {} (loop edges in orange)\n", (out / "slam/map.ply").string(),
                           (out / "slam/map.png").string());
  std::cout << fmt::format("plots: {}, {}\n", (out / "slam/trajectories.png").string(),
                           (out / "slam/eval_slam.png").string());
  std::cout << "trajectories: " << (out / "slam/poses.txt").string() << " (KITTI camera frame)\n";
}

int run_demo(const DemoOptions& options) {
  const StageTimer timer;
  if (options.gt_labels && options.segment.enabled())
    throw ConfigError("--gt-labels and --segment both choose the labels: give one");
  SaloamConfig config = options.config.resolve();
  if (uses_sgpr(parse_place_detector(config.loop.detector))) config.loop.sgpr_model = sgpr_model_path({}, config).string();
  const std::filesystem::path out(options.out);
  OutputFolder folder(out, "demo", kDemoOutputs);
  const std::filesystem::path sequence_dir = out / "sequence";
  const bool from_disk = options.reuse;
  if (from_disk) check_kept_sequence(options, sequence_dir);

  heading(fmt::format("1/2 SLAM on a simulated sequence: route '{}', {} beams, {} labels{}", options.sim.preset,
                      options.sim.beams,
                      options.gt_labels ? "ground-truth" : "noisy (emulated network)",
                      from_disk ? " (reusing " + sequence_dir.string() + ")" : ""));
  DemoSource source = open_demo_source(options, config, sequence_dir, from_disk);
  const SourceInfo info = source.frames->info();
  std::cout << fmt::format("{} frames; the simulator renders them {}\n", info.size(),
                           from_disk ? "from disk" : options.keep_sequence ? "ahead and writes them to " + sequence_dir.string()
                                                                             : "ahead, in memory");
  std::optional<OdometryRun> baseline;
  if (options.baseline) {
    create_folder(out / "odometry_baseline");
    baseline.emplace(without_semantics(config.odometry), out / "odometry_baseline", info.velo_to_cam);
  }
  const std::size_t shown = info.size() / 2;
  const std::vector<double> range_image_rows = LidarModel::hdl64e().elevation_deg;
  SlamRunOptions run_options;
  run_options.follow = [&](const FinishedFrame& frame) {
    if (baseline) baseline->add(frame.scan, frame.time, info.first_frame + frame.index);
    if (frame.index == shown) render_range_image(frame.scan, out / fmt::format("range_{:06d}.png", shown), range_image_rows);
  };
  OutputFolder slam_folder = open_slam_folder(out / "slam", info);
  const SlamRunResult slam = run_slam(*source.frames, config, load_loop_network(config), slam_folder, run_options);
  if (baseline) baseline->commit();
  if (slam.interrupted) {
    folder.finish("interrupted");
    return 130;
  }
  source.frames.reset();  // stops the simulator's thread; finishes the kept sequence folder

  std::optional<TrajectoryEvaluation> baseline_eval;
  if (baseline && info.camera_poses) baseline_eval = evaluate_baseline(out, *info.camera_poses, baseline->result().output_poses);
  heading("2/2 summary");
  print_summary(slam, baseline_eval);
  print_outputs(slam, timer.elapsed_s(), out);
  write_view_page(slam_folder, source.simulated && !options.keep_sequence ? source.simulated.get() : nullptr);
  folder.finish("complete");
  return 0;
}

const CommandRegistration kRegistration{Command{
    "demo", "Run the whole system on a simulated sequence it makes itself (simulate, SLAM, evaluation, map)", 0,
    [](CLI::App& app) {
      auto options = std::make_shared<DemoOptions>();
      app.add_option("--out", options->out, "Output folder (default demo_output)");
      app.add_option("--preset", options->sim.preset, "Simulated route: figure-eight (default), urban-loop, straight");
      app.add_option("--frames", options->frames, "Only frames A:B of the route (quicker runs)");
      app.add_option("--beams", options->sim.beams, "LiDAR beams: 64, 32 or 16")->check(CLI::IsMember({64, 32, 16}));
      app.add_option("--seed", options->sim.seed, "Simulation seed");
      app.add_flag("--gt-labels", options->gt_labels, "Use ground-truth labels instead of emulated network output");
      options->segment.add_to(app);
      app.add_flag("--keep-sequence", options->keep_sequence,
                   "Also write the simulated sequence to OUT/sequence (about 2.4 MB per 64-beam scan)");
      app.add_flag("--reuse", options->reuse, "Read OUT/sequence (kept by an earlier --keep-sequence) instead of simulating");
      app.add_flag("!--no-baseline", options->baseline, "Skip the label-agnostic odometry baseline");
      options->config.add_to(app);
      return [options] { return run_demo(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
