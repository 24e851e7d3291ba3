// `saloam demo`: the whole system end to end on data it makes itself.
// Simulates a labelled sequence (default: the ~1.6 km figure eight, which
// revisits places in the same and in the opposite direction; HDL-64E,
// emulated segmentation-network labels), runs the SLAM (semantic odometry
// with loop closure) and the label-agnostic odometry baseline, evaluates
// them against the ground truth, and writes the semantic map and pictures.

#include <cmath>
#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/core/cancellation.hpp"
#include "saloam/eval/evaluation_report.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/runs/odometry_run.hpp"
#include "saloam/runs/slam_run.hpp"
#include "saloam/sim/render.hpp"
#include "saloam/sim/simulator.hpp"

namespace saloam::cli {
namespace {

struct DemoOptions {
  std::string out = "demo_output";
  std::string preset = "figure-eight";
  std::string frames;
  int beams = 64;
  std::uint64_t seed = 1;
  bool gt_labels = false;
  bool reuse = false;
  ConfigOptions config;
};

void heading(const std::string& text) { std::cout << "\n== " << text << " ==\n" << std::flush; }

int run_demo(const DemoOptions& options) {
  const SaloamConfig config = options.config.resolve();
  const std::filesystem::path out(options.out);
  const std::filesystem::path sequence = out / "sequence";

  heading(fmt::format("1/4 simulate: preset '{}', {} beams, {} labels -> {}", options.preset, options.beams,
                      options.gt_labels ? "ground-truth" : "noisy (emulated network)", sequence.string()));
  if (options.reuse && std::filesystem::exists(sequence / "poses.txt")) {
    std::cout << "reusing the existing sequence (--reuse)\n";
  } else {
    std::filesystem::remove_all(sequence);
    SimulationOptions sim_options;
    sim_options.preset = options.preset;
    sim_options.beams = options.beams;
    sim_options.seed = options.seed;
    sim_options.labels = options.gt_labels ? LabelMode::kGroundTruth : LabelMode::kNoisy;
    if (!options.frames.empty()) {
      const auto range = FrameRange::parse(options.frames);
      sim_options.first_frame = range.first;
      sim_options.end_frame = range.end;
    }
    const auto summary = simulate_sequence(sim_options, sequence);
    std::cout << fmt::format("{} frames, {:.0f} k points per frame, {:.1f} s", summary.frames,
                             summary.frames ? summary.points / 1000.0 / summary.frames : 0.0, summary.seconds);
    if (!std::isnan(summary.miou)) std::cout << fmt::format(", label mIoU {:.1f} %", 100.0 * summary.miou);
    std::cout << "\n";
    if (summary.interrupted || stop_requested()) return 130;
  }

  const SequenceReader reader(sequence);
  const auto gt_camera = reader.camera_poses();

  heading(fmt::format("2/4 SLAM: semantic odometry + loop closure ({}) -> {}", config.loop.detector,
                      (out / "slam").string()));
  const SlamRunResult slam = run_slam(reader, config, load_loop_network(config, {}), out / "slam", {});
  if (slam.interrupted) return 130;
  std::cout << fmt::format("{} frames, median {:.1f} ms/frame ({:.1f} Hz), loop closure {:.2f} ms/frame amortised\n",
                           slam.frames, slam.median_frame_ms, 1000.0 / std::max(slam.median_frame_ms, 1e-9),
                           slam.mean_loop_ms);

  heading(fmt::format("3/4 odometry, label-agnostic baseline (--no-semantics) -> {}", (out / "odometry_baseline").string()));
  OdometryConfig baseline_config = config.odometry;
  baseline_config.use_semantics = false;
  const SequenceReader baseline_reader(sequence, SequenceOptions{std::nullopt, true});
  const OdometryRunResult baseline = run_odometry(baseline_reader, baseline_config, out / "odometry_baseline", {});
  if (baseline.interrupted) return 130;
  const TrajectoryEvaluation baseline_eval = evaluate_trajectories(gt_camera, baseline.output_poses);
  const EvaluationLabels baseline_labels{"sequence/poses.txt", "odometry_baseline/poses.txt"};
  write_evaluation_json(out / "eval_baseline.json", baseline_eval, baseline_labels);
  plot_evaluation(out / "eval_baseline.png", gt_camera, baseline.output_poses, baseline_eval, baseline_labels);

  heading("4/4 summary");
  std::cout << "| trajectory | KITTI t_err [%] | KITTI r_err [deg/100 m] | ATE RMSE [m] | RPE [m/frame] |\n"
               "|---|---|---|---|---|\n";
  auto row = [](const std::string& name, const TrajectoryEvaluation& e) {
    std::cout << fmt::format("| {} | {} | {} | {} | {} |\n", name, format_metric(e.kitti.t_err_percent, 3),
                             format_metric(e.kitti.r_err_deg_per_100m, 3), format_metric(e.ate.aligned.rmse, 3),
                             format_metric(e.rpe.trans_rmse_m, 4));
  };
  row("odometry, label-agnostic baseline", baseline_eval);
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
  const std::size_t shown = reader.size() / 2;
  render_range_image(reader.load_scan(shown), out / fmt::format("range_{:06d}.png", shown));
  std::cout << fmt::format("\nmap: {}, {} (loop edges in orange)\n", (out / "slam/map.ply").string(),
                           (out / "slam/map.png").string());
  std::cout << fmt::format("plots: {}, {}, {}\n", (out / "slam/trajectories.png").string(),
                           (out / "slam/eval_slam.png").string(), (out / "eval_baseline.png").string());
  std::cout << "trajectories: " << (out / "slam/poses.txt").string()
            << " (KITTI camera frame; compare with " << (sequence / "poses.txt").string() << ")\n";
  return 0;
}

const CommandRegistration kRegistration{Command{
    "demo", "Run the whole system on a simulated sequence it makes itself (simulate, SLAM, evaluation, map)", 0,
    [](CLI::App& app) {
      auto options = std::make_shared<DemoOptions>();
      app.add_option("--out", options->out, "Output folder (default demo_output)");
      app.add_option("--preset", options->preset, "Simulated route: figure-eight (default), urban-loop, straight");
      app.add_option("--frames", options->frames, "Only frames A:B of the route (quicker runs)");
      app.add_option("--beams", options->beams, "LiDAR beams: 64, 32 or 16")->check(CLI::IsMember({64, 32, 16}));
      app.add_option("--seed", options->seed, "Simulation seed");
      app.add_flag("--gt-labels", options->gt_labels, "Use ground-truth labels instead of emulated network output");
      app.add_flag("--reuse", options->reuse, "Reuse an existing simulated sequence in the output folder");
      options->config.add_to(app);
      return [options] { return run_demo(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
