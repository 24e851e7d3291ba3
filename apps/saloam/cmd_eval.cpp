// `saloam eval`: accuracy of an estimated trajectory against ground truth
// (KITTI relative error, ATE, RPE) as Markdown, optionally JSON and a plot;
// with --map, a saved map's keyframe error per session (runs/session_eval.hpp).

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>
#include <iostream>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/eval/evaluation_report.hpp"
#include "saloam/eval/trajectory_metrics.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/maps/map_format.hpp"
#include "saloam/runs/output_folder.hpp"
#include "saloam/runs/session_eval.hpp"
#include "saloam/runs/trajectory_pairing.hpp"

namespace saloam::cli {
namespace {

struct EvalOptions {
  std::vector<std::string> gt_files;  ///< one; with --map one sequence folder per session
  std::string map;
  std::string gt_file;
  std::string est_file;
  std::string json_file;
  std::string plot_file;
  std::string alignment = "se3";
  std::string calib_file;
};

/// eval's outputs never equal, hold or lie inside its inputs (core/path_rules.hpp), nor each other.
void check_paths(const EvalOptions& options) {
  PathRules rules;
  for (const std::string& gt : options.gt_files) rules.input("--gt", gt);
  rules.input("--est", options.est_file).input("--calib", options.calib_file).input("--map", options.map);
  rules.output("--json", options.json_file).output("--plot", options.plot_file).check();
}

/// `eval --map MAP --gt SEQ_0 --gt SEQ_1 ...`: per-session error of a saved map.
int run_map_eval(const EvalOptions& options) {
  if (!options.est_file.empty() || !options.plot_file.empty() || !options.calib_file.empty() ||
      options.alignment != "se3") {
    throw ConfigError("--map evaluates a map's sessions against their sequences (one SE(3) alignment): --est, "
                      "--plot, --calib and --align do not apply");
  }
  const SavedMap map = read_map(options.map);
  std::vector<std::vector<Pose>> truth;
  for (const std::string& gt : options.gt_files) truth.push_back(read_sequence_truth(gt));
  SessionEvaluation evaluation;
  try {
    evaluation = evaluate_sessions(map, truth);
  } catch (const std::invalid_argument& e) {
    throw InputError(options.map, e.what());
  }
  print_session_evaluation(std::cout, evaluation, options.gt_files);
  if (!options.json_file.empty()) {
    AtomicFile out(options.json_file);
    out.stream() << session_evaluation_json(evaluation, options.gt_files).dump(2) << '\n';
    out.commit();
    spdlog::info("wrote {}", options.json_file);
  }
  return 0;
}

int run_eval(EvalOptions options) {
  check_paths(options);
  if (!options.map.empty()) return run_map_eval(options);
  if (options.gt_files.size() != 1 || options.est_file.empty()) {
    throw ConfigError("eval compares one --gt with one --est (several --gt only with --map)");
  }
  options.gt_file = options.gt_files.front();
  TrajectoryPair pair = read_trajectory_pair(
      options.gt_file, options.est_file,
      options.calib_file.empty() ? std::nullopt : std::optional<std::filesystem::path>(options.calib_file));
  Trajectory& gt = pair.gt;
  Trajectory& est = pair.est;

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
      app.add_option("--gt", options->gt_files,
                     "Ground-truth trajectory (KITTI 12 columns or TUM 8 columns); with --map: the sequence folder "
                     "of each session, in the map's order")
          ->required();
      app.add_option("--est", options->est_file,
                     "Estimated trajectory, same format rules, matched by frame (a run's result starts at the first "
                     "frame its summary.json records, anything else at frame 0)");
      app.add_option("--map", options->map,
                     "A saved map (slam --save-map, slam --map, merge): its keyframes' error per session against "
                     "the --gt sequences after one SE(3) alignment, and its cross-session loop edges judged");
      app.add_option("--json", options->json_file, "Write all metrics (and per-frame errors) to this JSON file");
      app.add_option("--plot", options->plot_file, "Write a top-down PNG of ground truth vs aligned estimate");
      app.add_option("--align", options->alignment, "Alignment of the estimate for ATE: se3, sim3 or none")
          ->check(CLI::IsMember({"se3", "sim3", "none"}, CLI::ignore_case))
          ->capture_default_str();
      app.add_option("--calib", options->calib_file,
                     "KITTI calib.txt (Tr) to compare a TUM file (LiDAR frame) with a KITTI file (camera frame)");
      return [options] { return run_eval(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
