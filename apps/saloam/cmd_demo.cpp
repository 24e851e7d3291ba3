// `saloam demo`: the whole system end to end on data it makes itself.
// Simulates a labelled sequence (default: the ~1 km urban loop with a
// revisit, HDL-64E, emulated segmentation-network labels), runs the
// semantic odometry and the label-agnostic baseline, evaluates both against
// the ground truth, and writes the semantic map and pictures.

#include <cmath>
#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/core/cancellation.hpp"
#include "saloam/eval/evaluation_report.hpp"
#include "saloam/io/ply.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/mapping/map_render.hpp"
#include "saloam/runs/map_building.hpp"
#include "saloam/runs/odometry_run.hpp"
#include "saloam/sim/render.hpp"
#include "saloam/sim/simulator.hpp"

namespace saloam::cli {
namespace {

struct DemoOptions {
  std::string out = "demo_output";
  std::string preset = "urban-loop";
  std::string frames;
  int beams = 64;
  std::uint64_t seed = 1;
  bool gt_labels = false;
  bool reuse = false;
  ConfigOptions config;
};

void heading(const std::string& text) { std::cout << "\n== " << text << " ==\n" << std::flush; }

struct ModeResult {
  std::string name;
  OdometryRunResult run;
  TrajectoryEvaluation evaluation;
};

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
  std::vector<ModeResult> results;
  const std::vector<std::pair<std::string, bool>> modes{{"semantic", true}, {"baseline", false}};
  int step = 2;
  for (const auto& [name, semantics] : modes) {
    heading(fmt::format("{}/4 odometry, {} -> {}", step++, semantics ? "semantic (SA-LOAM)" : "label-agnostic baseline (--no-semantics)",
                        (out / ("odometry_" + name)).string()));
    OdometryConfig odom = config.odometry;
    odom.use_semantics = semantics;
    const SequenceReader mode_reader(sequence, SequenceOptions{std::nullopt, !semantics});
    ModeResult r{name, run_odometry(mode_reader, odom, out / ("odometry_" + name), {}), {}};
    if (r.run.interrupted) return 130;
    std::cout << fmt::format("{} frames, median {:.1f} ms/frame ({:.1f} Hz), worst {:.1f} ms\n", r.run.frames,
                             r.run.median_frame_ms(), 1000.0 / std::max(r.run.median_frame_ms(), 1e-9),
                             r.run.worst_frame_ms());
    r.evaluation = evaluate_trajectories(gt_camera, r.run.output_poses);
    const EvaluationLabels labels{"sequence/poses.txt", "odometry_" + name + "/poses.txt"};
    write_evaluation_json(out / ("eval_" + name + ".json"), r.evaluation, labels);
    plot_evaluation(out / ("eval_" + name + ".png"), gt_camera, r.run.output_poses, r.evaluation, labels);
    results.push_back(std::move(r));
  }

  heading("4/4 evaluation and map");
  std::cout << "| odometry | KITTI t_err [%] | KITTI r_err [deg/100 m] | ATE RMSE [m] | RPE [m/frame] | Hz (median) |\n"
               "|---|---|---|---|---|---|\n";
  for (const auto& r : results) {
    const auto& e = r.evaluation;
    std::cout << fmt::format("| {} | {} | {} | {} | {} | {:.1f} |\n", r.name, format_metric(e.kitti.t_err_percent, 3),
                             format_metric(e.kitti.r_err_deg_per_100m, 3), format_metric(e.ate.aligned.rmse, 3),
                             format_metric(e.rpe.trans_rmse_m, 4), 1000.0 / std::max(r.run.median_frame_ms(), 1e-9));
  }
  const auto& semantic = results.front();
  SemanticMapOptions map_options;
  map_options.voxel_size = 0.25;
  const LabelledCloud map = build_semantic_map(reader, semantic.run.lidar_poses, 0, map_options, 2);
  write_ply(out / "map.ply", map);
  render_top_down(out / "map.png", map, semantic.run.lidar_poses);
  const std::size_t shown = reader.size() / 2;
  render_range_image(reader.load_scan(shown), out / fmt::format("range_{:06d}.png", shown));
  std::cout << fmt::format("\nmap: {} ({} points), {}\n", (out / "map.ply").string(), map.size(),
                           (out / "map.png").string());
  std::cout << fmt::format("plots: {}, {}\n", (out / "eval_semantic.png").string(),
                           (out / "eval_baseline.png").string());
  std::cout << "trajectories: " << (out / "odometry_semantic/poses.txt").string()
            << " (KITTI camera frame; compare with " << (sequence / "poses.txt").string() << ")\n";
  return 0;
}

const CommandRegistration kRegistration{Command{
    "demo", "Run the whole system on a simulated sequence it makes itself (simulate, odometry, evaluation, map)", 0,
    [](CLI::App& app) {
      auto options = std::make_shared<DemoOptions>();
      app.add_option("--out", options->out, "Output folder (default demo_output)");
      app.add_option("--preset", options->preset, "Simulated route: urban-loop, figure-eight, straight");
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
