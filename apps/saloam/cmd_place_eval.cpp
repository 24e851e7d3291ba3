// `saloam place-eval`: place-recognition evaluation of SGPR, Scan Context,
// their hybrid or Semantic Scan Context (the loop detectors of `saloam
// slam`) on a sequence with ground-truth poses (runs/place_eval_run.hpp).
// Prints max F1, precision at 100 % recall and recall at 100 % precision;
// writes the precision-recall curve (CSV, PNG) and a summary.

#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/runs/place_eval_run.hpp"

namespace saloam::cli {
namespace {

struct PlaceEvalArgs {
  ConfigOptions config;
  SourceArgs source;
  std::string model;
  std::string out;
  std::string graphs;
  bool no_instances = false;
  PlaceEvalOptions run;
};

void print_result(const PlaceEvalArgs& args, const PlaceEvalResult& r, const std::filesystem::path& out) {
  std::cout << fmt::format("place-eval {} on {} ({} frames{}): {} positive, {} negative pairs\n", args.run.method,
                           args.source.path, r.frames,
                           r.left_out.empty() ? "" : fmt::format(", {} unreadable left out", r.left_out.size()),
                           r.summary.positives, r.summary.negatives);
  if (uses_sgpr(parse_place_detector(args.run.method))) std::cout << fmt::format("  mean graph size {:.1f} nodes\n", r.mean_nodes);
  if (r.summary.positives == 0) {
    spdlog::warn("no positive pairs (no revisit within {} m): the metrics are undefined",
                 args.run.protocol.positive_distance);
  } else {
    std::cout << fmt::format("  max F1                     {:.4f} (precision {:.4f}, recall {:.4f}, score >= {:.6g})\n",
                             r.summary.max_f1, r.summary.max_f1_precision, r.summary.max_f1_recall,
                             r.summary.max_f1_threshold);
    std::cout << fmt::format("  precision at 100 % recall  {:.4f}\n", r.summary.precision_at_full_recall);
    std::cout << fmt::format("  recall at 100 % precision  {:.4f}\n", r.summary.recall_at_full_precision);
  }
  std::cout << fmt::format("  descriptors {:.1f} ms/frame (one core), scoring {:.2f} s for {} pairs; wrote {}\n",
                           r.describe_ms_per_frame, r.score_wall_s, r.pairs, (out / "pr_curve.{csv,png}").string());
}

int run_place_eval_command(PlaceEvalArgs args) {
  PathRules rules;
  args.source.add_inputs(rules).input("--graphs", args.graphs).output("--out", args.out.empty() ? "place_eval_" + args.run.method : args.out, OutputUse::kFolder)
      .check();
  PlaceEvalOptions& run = args.run;
  if (!args.graphs.empty()) run.graphs = args.graphs;
  run.graph.use_instances = !args.no_instances;
  run.check();  // before the sequence is read
  SaloamConfig config = args.config.resolve();
  const PlaceDetector detector = parse_place_detector(run.method);
  if (uses_sgpr(detector)) {
    run.model = sgpr_model_path(args.model, config);
  } else {
    refuse_unused_model(args.model, run.method);
  }
  run.labels = args.source.segment.enabled() ? std::string("segmented in-process")
               : args.source.labels.empty()  ? std::string("labels/")
                                             : args.source.labels;
  const std::unique_ptr<FrameSource> source = args.source.open(!needs_labels(detector), config);
  const std::filesystem::path out = args.out.empty() ? "place_eval_" + run.method : args.out;
  const PlaceEvalResult result = run_place_eval(*source, config, run, out);
  if (result.interrupted) return 130;
  print_result(args, result, out);
  return 0;
}

const CommandRegistration kRegistration{Command{
    "place-eval", "Place-recognition evaluation (SGPR, Scan Context, hybrid or SSC) against ground-truth poses", 42,
    [](CLI::App& app) {
      auto args = std::make_shared<PlaceEvalArgs>();
      args->config.add_to(app);
      args->source.add_to(app, "Sequence folder (velodyne/, labels/, poses.txt, calib.txt)");
      app.add_option("--method", args->run.method,
                     "sgpr, scancontext, hybrid (mean of both scores) or ssc (Semantic Scan Context, loop.ssc.*)")
          ->check(CLI::IsMember({"sgpr", "scancontext", "hybrid", "ssc"}))
          ->capture_default_str();
      app.add_option("--model", args->model,
                     "SGPR weights (.sgw); default: config loop.sgpr_model, else the shipped models/sgpr/saloam.sgw");
      app.add_option("--out", args->out, "Output folder (default ./place_eval_<method>)");
      app.add_option("--positive", args->run.protocol.positive_distance, "[m] pairs within this distance are matches")
          ->check(positive_number())
          ->capture_default_str();
      app.add_option("--negative", args->run.protocol.negative_distance,
                     "[m] pairs beyond this distance are non-matches (more than --positive)")
          ->check(positive_number())
          ->capture_default_str();
      app.add_option("--exclude", args->run.protocol.exclude_recent, "most recent frames not compared with a query")
          ->check(non_negative_integer())
          ->capture_default_str();
      app.add_option("--negative-share", args->run.protocol.negative_share,
                     "share of the negative pairs evaluated, the same pairs in every run (SGPR's pair lists: 0.005 "
                     "with --exclude 0)")
          ->check(positive_number())
          ->check(CLI::Range(0.0, 1.0))
          ->capture_default_str();
      app.add_flag("--no-instances", args->no_instances, "Ignore instance ids when building graphs");
      app.add_flag("--save-graphs", args->run.save_graphs, "Also write every frame's graph to OUT/graphs/");
      app.add_option("--graphs", args->graphs,
                     "SGPR: read every frame's graph from DIR/NNNNNN.json (an earlier run's OUT/graphs/) instead of "
                     "building it from the scan; compares models on the same graphs without rebuilding them");
      app.add_flag("--save-scores", args->run.save_scores, "Also write every pair's score to OUT/pair_scores.csv");
      app.add_flag("--no-calib", args->source.no_calib,
                   "No calib.txt needed: match distances from poses.txt as given (LiDAR-frame poses)");
      return [args] { return run_place_eval_command(*args); };
    }}};

}  // namespace
}  // namespace saloam::cli
