#include "saloam/runs/place_eval_run.hpp"

#include <algorithm>
#include <mutex>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/path_rules.hpp"
#include "saloam/runs/output_folder.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/place/graph_json.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/viz/canvas.hpp"

namespace saloam {
namespace {

/// The descriptor of every frame, and what it took.
struct Descriptions {
  std::vector<PlaceDescriptor> descriptors;
  std::vector<std::uint8_t> readable;  ///< 0: left out (the scan could not be read)
  std::vector<double> describe_ms;     ///< per frame, on its worker thread
  std::vector<std::string> left_out;   ///< why each unreadable frame was left out
  double wall_s = 0;
};

/// One frame on its way through the describing pipeline.
struct FrameInput {
  std::size_t index = 0;
  bool readable = true;
  LabelledCloud scan;  ///< empty when the graphs are read from files
};

struct FrameDescriber {
  FrameSource& source;
  const PlaceRecognizer& recognizer;
  const PlaceEvalOptions& options;
  const std::filesystem::path& out_dir;
  Descriptions& d;

  [[nodiscard]] std::string file_name(std::size_t i) const {
    return frame_name(source.info().first_frame + i) + ".json";
  }

  // Serial, in frame order (a source serves its frames one by one). A frame
  // that cannot be read (missing, empty or truncated scan) is left out of the
  // evaluation with a warning instead of ending the whole run.
  FrameInput read(std::size_t i) {
    FrameInput input{i, true, {}};
    if (options.graphs) return input;
    try {
      input.scan = source.scan(i);
    } catch (const InputError& e) {
      input.readable = false;
      d.readable[i] = 0;
      d.left_out.push_back(e.what());
    }
    return input;
  }

  // In parallel: each frame writes only its own slots.
  void describe(const FrameInput& input) const {
    if (!input.readable) return;
    const std::size_t i = input.index;
    const StageTimer timer;
    // From an earlier run's graphs only the network runs, so several models
    // are compared on the very same graphs.
    d.descriptors[i] = options.graphs ? recognizer.describe_graph(read_graph_json(*options.graphs / file_name(i)))
                                      : recognizer.describe(input.scan);
    if (options.save_graphs && uses_sgpr(recognizer.detector())) {
      write_graph_json(out_dir / "graphs" / file_name(i), d.descriptors[i].graph);
    }
    d.describe_ms[i] = timer.elapsed_ms();
  }
};

const char* describe_label(PlaceDetector detector) {
  if (uses_sgpr(detector)) return "graphs + embeddings";
  return uses_ssc(detector) ? "semantic scan contexts" : "scan contexts";
}

// Runs `work(i)` for every frame in parallel with a progress bar; stops early on Ctrl-C.
template <class Work>
void for_each_frame(std::size_t count, const std::string& label, bool show_progress, Work&& work) {
  ProgressBar progress(count, label, show_progress);
  std::mutex progress_mutex;
  tbb::parallel_for(std::size_t{0}, count, [&](std::size_t i) {
    if (stop_requested()) return;
    work(i);
    const std::lock_guard lock(progress_mutex);
    progress.advance();
  });
  progress.finish();
}

// 1. One descriptor per frame (graph + pooled embedding, and/or Scan Context):
// read in order, described in parallel.
Descriptions describe_frames(FrameSource& source, const PlaceRecognizer& recognizer, const PlaceEvalOptions& options,
                             const std::filesystem::path& out_dir) {
  const std::size_t n = source.size();
  Descriptions d{std::vector<PlaceDescriptor>(n), std::vector<std::uint8_t>(n, 1), std::vector<double>(n, 0.0), {}, 0};
  FrameDescriber describer{source, recognizer, options, out_dir, d};
  ProgressBar progress(n, describe_label(recognizer.detector()), options.show_progress);
  std::mutex progress_mutex;
  const StageTimer timer;
  std::size_t next = 0;
  const auto read = [&](tbb::flow_control& control) {
    if (next == n || stop_requested()) {
      control.stop();
      return FrameInput{};
    }
    return describer.read(next++);
  };
  const auto describe = [&](const FrameInput& input) {
    describer.describe(input);
    const std::lock_guard lock(progress_mutex);
    progress.advance();
  };
  const auto tokens = static_cast<std::size_t>(2 * tbb::this_task_arena::max_concurrency());
  tbb::parallel_pipeline(tokens, tbb::make_filter<void, FrameInput>(tbb::filter_mode::serial_in_order, read) &
                                     tbb::make_filter<FrameInput, void>(tbb::filter_mode::parallel, describe));
  progress.finish();
  d.wall_s = timer.elapsed_s();
  std::sort(d.left_out.begin(), d.left_out.end());
  return d;
}

/// Every evaluated pair with its truth and score.
struct ScoredPairs {
  std::vector<PlacePair> pairs;
  std::vector<double> scores;
  std::vector<std::uint8_t> truth;
  double wall_s = 0;
};

// 2. Scores of every evaluated pair (grouped by query frame).
ScoredPairs score_pairs(const std::vector<Eigen::Vector3d>& positions, const Descriptions& d,
                        const PlaceRecognizer& recognizer, const PlaceEvalOptions& options) {
  const std::size_t n = positions.size();
  ScoredPairs s;
  s.pairs = place_pairs(positions, options.protocol);
  std::erase_if(s.pairs, [&](const PlacePair& p) { return !d.readable[p.query] || !d.readable[p.candidate]; });
  std::vector<std::size_t> query_start(n + 1, s.pairs.size());
  for (std::size_t k = s.pairs.size(); k-- > 0;) query_start[s.pairs[k].query] = k;
  for (std::size_t i = n; i-- > 0;) query_start[i] = std::min(query_start[i], query_start[i + 1]);
  s.scores.resize(s.pairs.size());
  s.truth.resize(s.pairs.size());
  for (std::size_t k = 0; k < s.pairs.size(); ++k) s.truth[k] = s.pairs[k].positive ? 1 : 0;
  const StageTimer timer;
  for_each_frame(n, "scoring pairs", options.show_progress, [&](std::size_t i) {
    const std::size_t begin = query_start[i], end = query_start[i + 1];
    if (begin == end) return;
    std::vector<const PlaceDescriptor*> candidates;
    candidates.reserve(end - begin);
    for (std::size_t k = begin; k < end; ++k) candidates.push_back(&d.descriptors[s.pairs[k].candidate]);
    const std::vector<PlaceMatch> matches = recognizer.match(d.descriptors[i], candidates);  // the query is the first graph
    for (std::size_t k = begin; k < end; ++k) s.scores[k] = matches[k - begin].score;
  });
  s.wall_s = timer.elapsed_s();
  return s;
}

void write_pair_scores(const std::filesystem::path& file, const ScoredPairs& s, std::size_t first_frame) {
  AtomicFile csv(file);
  csv.stream() << "query,candidate,positive,score\n";
  for (std::size_t k = 0; k < s.pairs.size(); ++k) {
    csv.stream() << fmt::format("{},{},{},{:.9g}\n", first_frame + s.pairs[k].query,
                                first_frame + s.pairs[k].candidate, s.truth[k], s.scores[k]);
  }
  csv.commit();
}

void write_curve(const std::filesystem::path& out, const std::string& method, const PrSummary& summary) {
  AtomicFile csv(out / "pr_curve.csv");
  csv.stream() << "threshold,precision,recall\n";
  for (const auto& p : thin_curve(summary, 2000)) {
    csv.stream() << fmt::format("{:.9g},{:.6f},{:.6f}\n", p.threshold, p.precision, p.recall);
  }
  csv.commit();
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

void write_summary(OutputFolder& folder, const SourceInfo& info, const PlaceEvalOptions& options,
                   const PlaceEvalResult& r) {
  nlohmann::json j{{"command", "place-eval"},
                   {"method", options.method},
                   {"sequence", std::filesystem::absolute(info.folder.value_or(info.name)).string()},
                   {"first_frame", info.first_frame},
                   {"frames", r.frames},
                   {"frames_left_out", r.left_out.size()},
                   {"labels", options.labels},
                   {"positive_distance", options.protocol.positive_distance},
                   {"negative_distance", options.protocol.negative_distance},
                   {"exclude_recent", options.protocol.exclude_recent},
                   {"negative_share", options.protocol.negative_share},
                   {"describe_ms_per_frame", r.describe_ms_per_frame},
                   {"describe_wall_s", r.describe_wall_s},
                   {"score_wall_s", r.score_wall_s},
                   {"max_f1", r.summary.max_f1},
                   {"max_f1_threshold", r.summary.max_f1_threshold},
                   {"max_f1_precision", r.summary.max_f1_precision},
                   {"max_f1_recall", r.summary.max_f1_recall},
                   {"precision_at_full_recall", r.summary.precision_at_full_recall},
                   {"recall_at_full_precision", r.summary.recall_at_full_precision},
                   {"positive_pairs", r.summary.positives},
                   {"negative_pairs", r.summary.negatives}};
  if (uses_sgpr(parse_place_detector(options.method))) {
    j["model"] = options.model.string();
    j["use_instances"] = options.graph.use_instances;
    j["mean_nodes"] = r.mean_nodes;
  }
  if (options.graphs) j["graphs"] = std::filesystem::absolute(*options.graphs).string();
  write_run_summary(folder, std::move(j));
}

// LiDAR positions of the ground truth (poses.txt through Tr; as given without Tr).
std::vector<Eigen::Vector3d> truth_positions(const SourceInfo& info) {
  if (!info.camera_poses) {
    throw InputError(info.folder.value_or(info.name), "no poses.txt: place-eval needs ground-truth poses");
  }
  const std::vector<Pose> poses =
      info.velo_to_cam ? camera_to_lidar_poses(*info.camera_poses, *info.velo_to_cam) : *info.camera_poses;
  std::vector<Eigen::Vector3d> positions;
  for (const auto& p : poses) positions.push_back(p.translation());
  return positions;
}

// An earlier run's graphs read from inside the output folder would be
// removed by the new run's clean start before they are read.
void check_graphs_outside(const PlaceEvalOptions& options, const std::filesystem::path& out_dir) {
  if (!options.graphs) return;
  if (path_within(comparable_path(*options.graphs), comparable_path(out_dir))) {
    throw ConfigError(fmt::format("--graphs {} lies in the output folder {}, which a new run clears: copy the graphs "
                                  "elsewhere or choose another --out",
                                  options.graphs->string(), out_dir.string()));
  }
}

PlaceRecognizer make_recognizer(PlaceDetector detector, const SaloamConfig& config, const PlaceEvalOptions& options) {
  std::optional<SgprNetwork> network;
  if (uses_sgpr(detector)) network.emplace(SgprNetwork::load(options.model));
  return PlaceRecognizer(detector, std::move(network), options.graph, ScanContextConfig{}, config.loop.ssc);
}

}  // namespace

void PlaceEvalOptions::check() const {
  // Pairs between the two distances count neither way; with the distances
  // equal or swapped a pair would be both a match and a non-match. (NaN fails
  // this test too.)
  if (!(protocol.positive_distance < protocol.negative_distance)) {
    throw ConfigError(fmt::format("--positive {} must be less than --negative {}", protocol.positive_distance,
                                  protocol.negative_distance));
  }
  if (!graphs) return;
  const PlaceDetector detector = parse_place_detector(method);
  if (!uses_sgpr(detector)) throw ConfigError("--graphs needs an SGPR method (sgpr, hybrid)");
  if (uses_scan_context(detector)) throw ConfigError("--graphs: --method hybrid also needs the scans; use --method sgpr");
  if (!std::filesystem::is_directory(*graphs)) throw InputError(*graphs, "graph folder (--graphs) not found");
}

PlaceEvalResult run_place_eval(FrameSource& source, const SaloamConfig& config, const PlaceEvalOptions& options,
                               const std::filesystem::path& out_dir) {
  options.check();
  const SourceInfo& info = source.info();
  const PlaceDetector detector = parse_place_detector(options.method);
  const std::vector<Eigen::Vector3d> positions = truth_positions(info);
  if (needs_labels(detector) && !info.has_labels) {
    throw InputError(info.folder.value_or(info.name),
                     fmt::format("no labels/ folder (give --labels DIR): {} needs semantic labels",
                                 uses_sgpr(detector) ? "SGPR" : "SSC"));
  }
  check_graphs_outside(options, out_dir);
  OutputFolder folder = open_run_folder(out_dir, info.folder, "place-eval", kPlaceEvalOutputs);
  const PlaceRecognizer recognizer = make_recognizer(detector, config, options);

  PlaceEvalResult result;
  result.frames = info.size();
  const Descriptions d = describe_frames(source, recognizer, options, out_dir);
  for (const auto& message : d.left_out) spdlog::warn("frame left out of the evaluation: {}", message);
  result.left_out = d.left_out;
  result.interrupted = stop_requested();
  if (result.interrupted) {
    folder.finish("interrupted");
    return result;
  }
  const ScoredPairs s = score_pairs(positions, d, recognizer, options);
  result.interrupted = stop_requested();
  if (result.interrupted) {
    folder.finish("interrupted");
    return result;
  }

  if (options.save_scores) write_pair_scores(out_dir / "pair_scores.csv", s, info.first_frame);
  result.summary = precision_recall(s.scores, s.truth);
  result.pairs = s.pairs.size();
  const std::size_t described = result.frames - result.left_out.size();
  double nodes = 0, describe_ms = 0;
  for (std::size_t i = 0; i < d.descriptors.size(); ++i) {
    nodes += static_cast<double>(d.descriptors[i].graph.size());
    describe_ms += d.describe_ms[i];
  }
  result.mean_nodes = described ? nodes / static_cast<double>(described) : 0.0;
  result.describe_ms_per_frame = described ? describe_ms / static_cast<double>(described) : 0.0;
  result.describe_wall_s = d.wall_s;
  result.score_wall_s = s.wall_s;
  write_curve(out_dir, options.method, result.summary);
  write_summary(folder, info, options, result);
  return result;
}

}  // namespace saloam
