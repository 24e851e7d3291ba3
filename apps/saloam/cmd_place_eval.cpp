// `saloam place-eval`: place-recognition evaluation of SGPR, Scan Context,
// their hybrid or Semantic Scan Context (the loop detectors of `saloam slam`,
// one PlaceRecognizer) on
// a sequence with ground-truth poses (SGPR's protocol: every frame against
// the earlier frames except the last 50; match within 3 m, non-match beyond
// 20 m). Prints max F1, precision at 100 % recall and recall at 100 %
// precision; writes the precision-recall curve (CSV, PNG) and a summary.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <iostream>
#include <mutex>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include "command.hpp"
#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/place/graph_json.hpp"
#include "saloam/place/place_recognition.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/place/scan_context.hpp"
#include "saloam/place/semantic_graph.hpp"
#include "saloam/place/sgpr_network.hpp"
#include "saloam/viz/canvas.hpp"

namespace saloam::cli {
namespace {

struct PlaceEvalArgs {
  ConfigOptions config;
  std::string sequence;
  std::string method = "sgpr";
  std::string model;
  std::string labels;
  std::string out;
  PlaceEvalConfig protocol;
  bool no_instances = false;
  bool save_graphs = false;
  std::string graphs;  ///< read the graphs from here (--save-graphs output) instead of building them
  bool save_scores = false;
  bool no_calib = false;
};

/// Runs `work(i)` for every frame in parallel with a progress bar; stops early on Ctrl-C.
template <class Work>
void for_each_frame(std::size_t count, const std::string& label, Work&& work) {
  ProgressBar progress(count, label);
  std::mutex progress_mutex;
  tbb::parallel_for(std::size_t{0}, count, [&](std::size_t i) {
    if (stop_requested()) return;
    work(i);
    const std::lock_guard lock(progress_mutex);
    progress.advance();
  });
  progress.finish();
}

void write_outputs(const std::filesystem::path& out, const std::string& method, const PrSummary& summary,
                   const nlohmann::json& info) {
  {
    std::ofstream csv(out / "pr_curve.csv");
    if (!csv) throw InputError(out / "pr_curve.csv", "cannot create file");
    csv << "threshold,precision,recall\n";
    for (const auto& p : thin_curve(summary, 2000)) csv << fmt::format("{:.9g},{:.6f},{:.6f}\n", p.threshold, p.precision, p.recall);
  }
  {
    nlohmann::json j = info;
    j["max_f1"] = summary.max_f1;
    j["max_f1_threshold"] = summary.max_f1_threshold;
    j["max_f1_precision"] = summary.max_f1_precision;
    j["max_f1_recall"] = summary.max_f1_recall;
    j["precision_at_full_recall"] = summary.precision_at_full_recall;
    j["recall_at_full_precision"] = summary.recall_at_full_precision;
    j["positive_pairs"] = summary.positives;
    j["negative_pairs"] = summary.negatives;
    std::ofstream(out / "summary.json") << j.dump(2) << '\n';
  }
  Plot plot(800, 640);
  plot.set_range(0, 1, 0, 1.02, false);
  plot.set_title(fmt::format("{}: max F1 {:.3f}", method, summary.max_f1));
  plot.set_labels("recall", "precision");
  std::vector<Eigen::Vector2d> line;
  for (const auto& p : thin_curve(summary, 4000)) line.emplace_back(p.recall, p.precision);
  plot.line(line, Rgb{31, 119, 180}, 2.0);
  plot.marker({summary.max_f1_recall, summary.max_f1_precision}, Rgb{214, 39, 40}, 5.0,
              fmt::format("max F1 {:.3f}", summary.max_f1));
  plot.save_png(out / "pr_curve.png");
}

int run_place_eval(const PlaceEvalArgs& args) {
  // Pairs between the two distances count neither way; with the distances
  // equal or swapped a pair would be both a match and a non-match. (The
  // options' checks reject values <= 0 and infinity; NaN fails this test.)
  const PlaceEvalConfig& protocol = args.protocol;
  if (!(protocol.positive_distance < protocol.negative_distance)) {
    throw ConfigError(fmt::format("--positive {} must be less than --negative {}", protocol.positive_distance,
                                  protocol.negative_distance));
  }
  const SaloamConfig config = args.config.resolve();
  const PlaceDetector detector = parse_place_detector(args.method);
  const bool sgpr = uses_sgpr(detector);
  SequenceOptions options;
  if (!args.labels.empty()) options.labels_dir = args.labels;
  options.ignore_labels = !needs_labels(detector);
  const SequenceReader reader(args.sequence, options);
  if (!reader.has_poses()) throw InputError(args.sequence, "no poses.txt: place-eval needs ground-truth poses");
  if (needs_labels(detector) && !reader.has_labels())
    throw InputError(args.sequence, fmt::format("no labels/ folder (give --labels DIR): {} needs semantic labels",
                                                sgpr ? "SGPR" : "SSC"));
  // Distances between LiDAR positions; with --no-calib those of poses.txt as given.
  if (!args.no_calib && !reader.has_calib()) {
    throw InputError(reader.root() / "calib.txt", "not found: needed for the LiDAR positions of poses.txt; pass "
                                                  "--no-calib to use the poses as given (LiDAR frame)");
  }
  const std::vector<Pose> poses = args.no_calib ? reader.camera_poses() : reader.lidar_poses();
  std::vector<Eigen::Vector3d> positions;
  for (const auto& p : poses) positions.push_back(p.translation());
  const std::size_t n = reader.size();

  const std::filesystem::path out = args.out.empty() ? std::filesystem::path("place_eval_" + args.method) : std::filesystem::path(args.out);
  create_folder(out);
  if (args.save_graphs) create_folder(out / "graphs");

  std::optional<SgprNetwork> network;
  const std::filesystem::path model = sgpr ? sgpr_model_path(args.model, config) : std::filesystem::path();
  if (sgpr) network.emplace(SgprNetwork::load(model));
  GraphBuilderConfig graph_config;
  graph_config.use_instances = !args.no_instances;
  const PlaceRecognizer recognizer(detector, std::move(network), graph_config, ScanContextConfig{}, config.loop.ssc);

  // 1. One descriptor per frame (graph + pooled embedding, and/or Scan Context).
  std::vector<PlaceDescriptor> descriptors(n);
  std::atomic<double> describe_seconds{0};
  const auto t0 = std::chrono::steady_clock::now();
  // A frame that cannot be read (missing, empty or truncated scan) is left out
  // of the evaluation with a warning instead of ending the whole run.
  std::vector<std::uint8_t> readable(n, 1);
  std::mutex skipped_mutex;
  std::vector<std::string> skipped;
  const char* describe_label = sgpr ? "graphs + embeddings" : uses_ssc(detector) ? "semantic scan contexts" : "scan contexts";
  if (!args.graphs.empty() && !sgpr) throw ConfigError("--graphs needs an SGPR method (sgpr, hybrid)");
  if (!args.graphs.empty() && uses_scan_context(detector))
    throw ConfigError("--graphs: --method hybrid also needs the scans; use --method sgpr");
  if (!args.graphs.empty() && !std::filesystem::is_directory(args.graphs))
    throw InputError(args.graphs, "graph folder (--graphs) not found");
  for_each_frame(n, describe_label, [&](std::size_t i) {
    if (!args.graphs.empty()) {
      // The graphs of an earlier run (--save-graphs): only the network runs,
      // so several models are compared on the very same graphs.
      const auto start = std::chrono::steady_clock::now();
      descriptors[i] = recognizer.describe_graph(read_graph_json(std::filesystem::path(args.graphs) / (frame_name(i) + ".json")));
      if (args.save_graphs) write_graph_json(out / "graphs" / (frame_name(i) + ".json"), descriptors[i].graph);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      double expected = describe_seconds.load();
      while (!describe_seconds.compare_exchange_weak(expected, expected + s)) {
      }
      return;
    }
    LabelledCloud cloud;
    try {
      cloud = reader.load_scan(i);
    } catch (const InputError& e) {
      readable[i] = 0;
      const std::lock_guard lock(skipped_mutex);
      skipped.push_back(e.what());
      return;
    }
    const auto start = std::chrono::steady_clock::now();
    descriptors[i] = recognizer.describe(cloud);
    if (args.save_graphs && sgpr) write_graph_json(out / "graphs" / (frame_name(i) + ".json"), descriptors[i].graph);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double expected = describe_seconds.load();
    while (!describe_seconds.compare_exchange_weak(expected, expected + s)) {
    }
  });
  std::sort(skipped.begin(), skipped.end());
  for (const auto& message : skipped) spdlog::warn("frame left out of the evaluation: {}", message);
  if (stop_requested()) return 130;
  const double describe_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // 2. Scores of every evaluated pair (grouped by query frame).
  std::vector<PlacePair> pairs = place_pairs(positions, args.protocol);
  std::erase_if(pairs, [&](const PlacePair& p) { return !readable[p.query] || !readable[p.candidate]; });
  std::vector<std::size_t> query_start(n + 1, pairs.size());
  for (std::size_t k = pairs.size(); k-- > 0;) query_start[pairs[k].query] = k;
  for (std::size_t i = n; i-- > 0;) query_start[i] = std::min(query_start[i], query_start[i + 1]);
  std::vector<double> scores(pairs.size());
  std::vector<std::uint8_t> truth(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) truth[k] = pairs[k].positive ? 1 : 0;
  const auto t1 = std::chrono::steady_clock::now();
  for_each_frame(n, "scoring pairs", [&](std::size_t i) {
    const std::size_t begin = query_start[i], end = query_start[i + 1];
    if (begin == end) return;
    std::vector<const PlaceDescriptor*> candidates;
    candidates.reserve(end - begin);
    for (std::size_t k = begin; k < end; ++k) candidates.push_back(&descriptors[pairs[k].candidate]);
    const std::vector<PlaceMatch> matches = recognizer.match(descriptors[i], candidates);  // the query is the first graph
    for (std::size_t k = begin; k < end; ++k) scores[k] = matches[k - begin].score;
  });
  if (stop_requested()) return 130;
  const double score_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();

  if (args.save_scores) {
    std::ofstream csv(out / "pair_scores.csv");
    if (!csv) throw InputError(out / "pair_scores.csv", "cannot create file");
    csv << "query,candidate,positive,score\n";
    for (std::size_t k = 0; k < pairs.size(); ++k)
      csv << fmt::format("{},{},{},{:.9g}\n", pairs[k].query, pairs[k].candidate, truth[k], scores[k]);
  }
  const PrSummary summary = precision_recall(scores, truth);
  nlohmann::json info;
  info["method"] = args.method;
  info["sequence"] = std::filesystem::absolute(args.sequence).string();
  info["frames"] = n;
  info["frames_left_out"] = skipped.size();
  if (sgpr) {
    info["model"] = model.string();
    info["use_instances"] = graph_config.use_instances;
    double mean_nodes = 0;
    for (const auto& d : descriptors) mean_nodes += static_cast<double>(d.graph.size());
    const std::size_t described = n - skipped.size();
    info["mean_nodes"] = described ? mean_nodes / static_cast<double>(described) : 0.0;
  }
  info["labels"] = args.labels.empty() ? std::string("labels/") : args.labels;
  if (!args.graphs.empty()) info["graphs"] = std::filesystem::absolute(args.graphs).string();
  info["positive_distance"] = args.protocol.positive_distance;
  info["negative_distance"] = args.protocol.negative_distance;
  info["exclude_recent"] = args.protocol.exclude_recent;
  info["negative_share"] = args.protocol.negative_share;
  info["describe_ms_per_frame"] =
      n > skipped.size() ? 1000.0 * describe_seconds.load() / static_cast<double>(n - skipped.size()) : 0.0;
  info["describe_wall_s"] = describe_wall;
  info["score_wall_s"] = score_wall;
  write_outputs(out, args.method, summary, info);

  std::cout << fmt::format("place-eval {} on {} ({} frames{}): {} positive, {} negative pairs\n", args.method,
                           args.sequence, n,
                           skipped.empty() ? "" : fmt::format(", {} unreadable left out", skipped.size()),
                           summary.positives, summary.negatives);
  if (sgpr) std::cout << fmt::format("  mean graph size {:.1f} nodes\n", info["mean_nodes"].get<double>());
  if (summary.positives == 0) {
    spdlog::warn("no positive pairs (no revisit within {} m): the metrics are undefined", args.protocol.positive_distance);
  } else {
    std::cout << fmt::format("  max F1                     {:.4f} (precision {:.4f}, recall {:.4f}, score >= {:.6g})\n",
                             summary.max_f1, summary.max_f1_precision, summary.max_f1_recall, summary.max_f1_threshold);
    std::cout << fmt::format("  precision at 100 % recall  {:.4f}\n", summary.precision_at_full_recall);
    std::cout << fmt::format("  recall at 100 % precision  {:.4f}\n", summary.recall_at_full_precision);
  }
  std::cout << fmt::format("  descriptors {:.1f} ms/frame (one core), scoring {:.2f} s for {} pairs; wrote {}\n",
                           info["describe_ms_per_frame"].get<double>(), score_wall, pairs.size(),
                           (out / "pr_curve.{csv,png}").string());
  return 0;
}

const CommandRegistration kRegistration{Command{
    "place-eval", "Place-recognition evaluation (SGPR, Scan Context, hybrid or SSC) against ground-truth poses", 42,
    [](CLI::App& app) {
      auto args = std::make_shared<PlaceEvalArgs>();
      args->config.add_to(app);
      app.add_option("sequence", args->sequence, "Sequence folder (velodyne/, labels/, poses.txt, calib.txt)")->required();
      app.add_option("--method", args->method,
                     "sgpr, scancontext, hybrid (mean of both scores) or ssc (Semantic Scan Context, loop.ssc.*)")
          ->check(CLI::IsMember({"sgpr", "scancontext", "hybrid", "ssc"}))
          ->capture_default_str();
      app.add_option("--model", args->model,
                     "SGPR weights (.sgw); default: config loop.sgpr_model, else the shipped models/sgpr/saloam.sgw");
      app.add_option("--labels", args->labels, "Folder of .label files to use instead of labels/");
      app.add_option("--out", args->out, "Output folder (default ./place_eval_<method>)");
      app.add_option("--positive", args->protocol.positive_distance, "[m] pairs within this distance are matches")
          ->check(positive_number())
          ->capture_default_str();
      app.add_option("--negative", args->protocol.negative_distance,
                     "[m] pairs beyond this distance are non-matches (more than --positive)")
          ->check(positive_number())
          ->capture_default_str();
      app.add_option("--exclude", args->protocol.exclude_recent, "most recent frames not compared with a query")
          ->check(non_negative_integer())
          ->capture_default_str();
      app.add_option("--negative-share", args->protocol.negative_share,
                     "share of the negative pairs evaluated, the same pairs in every run (SGPR's pair lists: 0.005 "
                     "with --exclude 0)")
          ->check(positive_number())
          ->check(CLI::Range(0.0, 1.0))
          ->capture_default_str();
      app.add_flag("--no-instances", args->no_instances, "Ignore instance ids when building graphs");
      app.add_flag("--save-graphs", args->save_graphs, "Also write every frame's graph to OUT/graphs/");
      app.add_option("--graphs", args->graphs,
                     "SGPR: read every frame's graph from DIR/NNNNNN.json (an earlier run's OUT/graphs/) instead of "
                     "building it from the scan; compares models on the same graphs without rebuilding them");
      app.add_flag("--save-scores", args->save_scores, "Also write every pair's score to OUT/pair_scores.csv");
      app.add_flag("--no-calib", args->no_calib,
                   "No calib.txt needed: match distances from poses.txt as given (LiDAR-frame poses)");
      return [args] { return run_place_eval(*args); };
    }}};

}  // namespace
}  // namespace saloam::cli
