// `saloam eval`: accuracy of an estimated trajectory against ground truth
// (KITTI relative error, ATE, RPE) as Markdown, optionally JSON and a plot.

#include <iostream>
#include <memory>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/error.hpp"
#include "saloam/eval/evaluation_report.hpp"
#include "saloam/eval/trajectory_metrics.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace saloam::cli {
namespace {

struct EvalOptions {
  std::string gt_file;
  std::string est_file;
  std::string json_file;
  std::string plot_file;
  std::string alignment = "se3";
};

int run_eval(const EvalOptions& options) {
  const Trajectory gt = read_trajectory(options.gt_file);
  const Trajectory est = read_trajectory(options.est_file);

  EvaluationOptions eval_options;
  eval_options.alignment = parse_alignment(options.alignment);  // validated by CLI11 already

  TrajectoryEvaluation evaluation;
  try {
    evaluation = evaluate_trajectories(gt.poses, est.poses, eval_options);
  } catch (const std::invalid_argument& e) {
    throw InputError(options.est_file, e.what());
  }
  for (const auto& warning : evaluation.warnings) spdlog::warn("{}", warning);

  const EvaluationLabels labels{std::filesystem::path(options.gt_file).filename().string(),
                                std::filesystem::path(options.est_file).filename().string()};
  print_evaluation_markdown(std::cout, evaluation, labels);
  if (!options.json_file.empty()) {
    write_evaluation_json(options.json_file, evaluation, labels);
    spdlog::info("wrote {}", options.json_file);
  }
  if (!options.plot_file.empty()) {
    plot_evaluation(options.plot_file, gt.poses, est.poses, evaluation, labels);
    spdlog::info("wrote {}", options.plot_file);
  }
  return 0;
}

const CommandRegistration kRegistration{Command{
    "eval", "Evaluate an estimated trajectory against ground truth (KITTI relative error, ATE, RPE)", 50,
    [](CLI::App& app) {
      auto options = std::make_shared<EvalOptions>();
      app.add_option("--gt", options->gt_file, "Ground-truth trajectory (KITTI 12 columns or TUM 8 columns)")
          ->required();
      app.add_option("--est", options->est_file, "Estimated trajectory, same format rules, matched by line index")
          ->required();
      app.add_option("--json", options->json_file, "Write all metrics (and per-frame errors) to this JSON file");
      app.add_option("--plot", options->plot_file, "Write a top-down PNG of ground truth vs aligned estimate");
      app.add_option("--align", options->alignment, "Alignment of the estimate for ATE: se3, sim3 or none")
          ->check(CLI::IsMember({"se3", "sim3", "none"}, CLI::ignore_case))
          ->capture_default_str();
      return [options] { return run_eval(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
