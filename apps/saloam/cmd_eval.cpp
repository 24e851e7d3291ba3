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

/// TUM files are LiDAR-frame poses (as saloam writes poses_tum.txt), KITTI
/// files camera-frame poses (poses.txt): comparing one with the other needs
/// Tr, which converts the TUM side to the camera frame (P = Tr Q Tr^-1).
void make_frames_consistent(const EvalOptions& options, Trajectory& gt, TrajectoryFormat gt_format, Trajectory& est,
                            TrajectoryFormat est_format) {
  if (gt_format == est_format) {
    if (!options.calib_file.empty()) {
      spdlog::warn("--calib unused: both files are {}", gt_format == TrajectoryFormat::kTum ? "TUM" : "KITTI");
    }
    return;
  }
  const bool est_is_tum = est_format == TrajectoryFormat::kTum;
  const std::string& tum_file = est_is_tum ? options.est_file : options.gt_file;
  const std::string& kitti_file = est_is_tum ? options.gt_file : options.est_file;
  if (options.calib_file.empty()) {
    throw InputError(tum_file, fmt::format("TUM trajectory (LiDAR frame, as poses_tum.txt) compared with the KITTI "
                                           "trajectory {} (camera frame, as poses.txt): pass --calib SEQ/calib.txt "
                                           "to convert it to the camera frame, or compare two files of one format",
                                           kitti_file));
  }
  Trajectory& tum = est_is_tum ? est : gt;
  tum.poses = lidar_to_camera_poses(tum.poses, read_velo_to_cam(options.calib_file));
}

/// A simulated sequence whose trajectory's heights do not fit one ground has
/// poses_sensor.txt beside poses.txt: where the scans were really taken. An
/// odometry drifts from those, so scoring it against poses.txt adds the
/// trajectory's own height errors to its error.
void warn_if_scans_were_taken_elsewhere(const std::filesystem::path& gt_file) {
  if (gt_file.filename() != "poses.txt") return;
  const auto sensor = gt_file.parent_path() / "poses_sensor.txt";
  if (!std::filesystem::is_regular_file(sensor)) return;
  spdlog::warn("{} has {} beside it: the simulator took this sequence's scans there (it rode the sensor on the ground "
               "where the trajectory's heights do not fit one); score an odometry against --gt {}",
               gt_file.string(), sensor.filename().string(), sensor.string());
}

/// eval's outputs never equal, hold or lie inside its inputs (core/path_rules.hpp), nor each other.
void check_paths(const EvalOptions& options) {
  PathRules rules;
  for (const std::string& gt : options.gt_files) rules.input("--gt", gt);
  rules.input("--est", options.est_file).input("--calib", options.calib_file).input("--map", options.map);
  rules.output("--json", options.json_file).output("--plot", options.plot_file).check();
}

/// `trajectory` from its `skip`-th pose on, re-based on that pose (world =
/// the first pose kept, as a run's results are).
void drop_first(Trajectory& trajectory, std::size_t skip, const std::string& file, std::size_t first_frame) {
  if (skip >= trajectory.size()) {
    throw InputError(file, fmt::format("{} poses, none of them at frame {} where the other trajectory starts",
                                       trajectory.size(), first_frame));
  }
  const auto begin = static_cast<std::ptrdiff_t>(skip);
  trajectory.poses.erase(trajectory.poses.begin(), trajectory.poses.begin() + begin);
  trajectory.timestamps.erase(trajectory.timestamps.begin(), trajectory.timestamps.begin() + begin);
  const Pose rebase = trajectory.poses.front().inverse();
  for (Pose& pose : trajectory.poses) pose = orthonormalized(rebase * pose);
}

/// Pairs the poses by frame: a run's result starts at the first frame its
/// summary.json records (`odom SEQ --frames 5:` writes frames 5, 6, ...),
/// a sequence's poses.txt at frame 0.
void pair_by_frame(const EvalOptions& options, Trajectory& gt, Trajectory& est) {
  const std::size_t gt_first = recorded_first_frame(options.gt_file).value_or(0);
  const std::size_t est_first = recorded_first_frame(options.est_file).value_or(0);
  if (gt_first == est_first) return;
  if (est_first > gt_first) {
    drop_first(gt, est_first - gt_first, options.gt_file, est_first);
  } else {
    drop_first(est, gt_first - est_first, options.est_file, gt_first);
  }
  spdlog::info("pairing by frame: the estimate starts at frame {}, the ground truth at frame {} (from the runs' "
               "summary.json)",
               est_first, gt_first);
}

/// Two TUM files carry their times: their poses are paired by time (the
/// nearest within 0.02 s, or half the ground truth's median interval when
/// that is less), never by line; poses without a partner are left out.
void pair_by_time(const EvalOptions& options, Trajectory& gt, Trajectory& est) {
  double tolerance = 0.02;  // [s] TUM's associate.py
  if (gt.timestamps.size() > 1) {
    std::vector<double> gaps;
    for (std::size_t i = 1; i < gt.timestamps.size(); ++i) gaps.push_back(gt.timestamps[i] - gt.timestamps[i - 1]);
    std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2), gaps.end());
    tolerance = std::min(tolerance, 0.5 * gaps[gaps.size() / 2]);
  }
  const auto pairs = associate_by_time(gt.timestamps, est.timestamps, tolerance);
  if (pairs.size() < 2) {
    throw InputError(options.est_file,
                     fmt::format("{} of its {} times ({:.9f}..{:.9f}) lie within {:.3g} s of one of the ground "
                                 "truth's {} ({:.9f}..{:.9f}): TUM files are paired by time (do their clocks differ?)",
                                 pairs.size(), est.size(), est.timestamps.front(), est.timestamps.back(), tolerance,
                                 gt.size(), gt.timestamps.front(), gt.timestamps.back()));
  }
  Trajectory paired_gt, paired_est;
  for (const auto& [g, e] : pairs) {
    paired_gt.timestamps.push_back(gt.timestamps[g]);
    paired_gt.poses.push_back(gt.poses[g]);
    paired_est.timestamps.push_back(est.timestamps[e]);
    paired_est.poses.push_back(est.poses[e]);
  }
  if (pairs.size() != gt.size() || pairs.size() != est.size()) {
    spdlog::warn("paired {} poses by time (within {:.3g} s): {} of the ground truth's {} and {} of the estimate's {} "
                 "have no partner and are left out",
                 pairs.size(), tolerance, gt.size() - pairs.size(), gt.size(), est.size() - pairs.size(), est.size());
  }
  gt = std::move(paired_gt);
  est = std::move(paired_est);
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
  warn_if_scans_were_taken_elsewhere(options.gt_file);
  TrajectoryFormat gt_format{}, est_format{};
  Trajectory gt = read_trajectory(options.gt_file, &gt_format);
  Trajectory est = read_trajectory(options.est_file, &est_format);
  make_frames_consistent(options, gt, gt_format, est, est_format);
  if (gt_format == TrajectoryFormat::kTum && est_format == TrajectoryFormat::kTum) {
    pair_by_time(options, gt, est);
  } else {
    pair_by_frame(options, gt, est);
  }

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
