#include "saloam/train/graph_dataset.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <fstream>
#include <mutex>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <yaml-cpp/yaml.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/place/graph_json.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sim/trajectories.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

std::vector<Eigen::Vector3d> positions_of(const std::vector<Pose>& lidar_poses) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(lidar_poses.size());
  for (const auto& p : lidar_poses) out.push_back(p.translation());
  return out;
}

nlohmann::json graph_config_json(const GraphBuilderConfig& c) {
  return {{"tolerance", c.tolerance},       {"min_cluster_size", c.min_cluster_size},
          {"max_cluster_size", c.max_cluster_size}, {"use_instances", c.use_instances},
          {"min_instance_points", c.min_instance_points}, {"max_nodes", c.max_nodes},
          {"edge_distance", c.edge_distance}};
}

/// Builds graph[i] = make(i) for every i in parallel, with a progress bar.
template <class Make>
std::vector<SemanticGraph> build_all(std::size_t count, const std::string& label, bool show_progress, Make&& make) {
  std::vector<SemanticGraph> graphs(count);
  ProgressBar progress(count, label, show_progress);
  std::mutex mutex;
  tbb::parallel_for(std::size_t{0}, count, [&](std::size_t i) {
    if (stop_requested()) return;
    graphs[i] = make(i);
    const std::lock_guard lock(mutex);
    progress.advance();
  });
  progress.finish();
  return graphs;
}

GraphSequence simulated_graphs(const SourceSpec& spec, const GraphBuilderConfig& graph_config, bool show_progress) {
  const SimulatedSequence sequence(simulation_options(spec));
  GraphSequence out;
  out.name = spec.name();
  // The sensor poses are where the scans were really taken (FORMAT of poses_sensor.txt).
  out.positions = positions_of(camera_to_lidar_poses(sequence.sensor_camera_poses(), sequence.velo_to_cam()));
  out.graphs = build_all(sequence.size(), "graphs of " + out.name, show_progress,
                         [&](std::size_t i) { return build_semantic_graph(sequence.render(i).cloud, graph_config); });
  return out;
}

GraphSequence folder_graphs(const SourceSpec& spec, const GraphBuilderConfig& graph_config, bool show_progress) {
  SequenceOptions options;
  if (!spec.labels.empty()) options.labels_dir = spec.labels;
  const SequenceReader reader(spec.path, options);
  if (!reader.has_poses()) throw InputError(spec.path / "poses.txt", "missing: training needs ground-truth poses");
  if (!reader.has_labels()) throw InputError(spec.path, "no labels (labels/ or the recipe's labels: folder)");
  if (!reader.has_calib()) throw InputError(spec.path / "calib.txt", "missing: needed for the LiDAR positions");
  const auto [first, end] = FrameRange::parse(spec.frames, "frames").clip(reader.size(), "frames");
  std::vector<std::size_t> frames;
  for (std::size_t i = first; i < end; i += spec.frame_step) frames.push_back(i);
  const auto all_positions = positions_of(reader.lidar_poses());
  GraphSequence out;
  out.name = spec.name();
  for (const auto i : frames) out.positions.push_back(all_positions.at(i));
  out.graphs = build_all(frames.size(), "graphs of " + out.name, show_progress,
                         [&](std::size_t k) { return build_semantic_graph(reader.load_scan(frames[k]), graph_config); });
  return out;
}

// Graph caches of a few thousand frames are tens of MB.
constexpr std::size_t kMaxGraphCacheBytes = std::size_t{1} << 30;

// The cached graphs when `file` holds them for `key`; nullopt when there is
// none, it is stale, or damaged (a warning: it is then rebuilt). Anything
// but a regular file in its place is an error (read_file).
std::optional<GraphSequence> read_cache(const fs::path& file, const nlohmann::json& key) {
  if (!path_taken(file)) return std::nullopt;
  const nlohmann::json j =
      nlohmann::json::parse(read_file(file, kMaxGraphCacheBytes, "graph cache"), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object() || !j.contains("key")) {
    spdlog::warn("{}: not a graph cache (damaged?); rebuilding it", plain_error_text(file.string()));
    return std::nullopt;
  }
  if (j["key"] != key) return std::nullopt;
  try {
    GraphSequence out;
    out.name = j.at("name").get<std::string>();
    for (const auto& g : j.at("graphs")) out.graphs.push_back(graph_from_json(g, file));
    for (const auto& p : j.at("positions")) {
      const Eigen::Vector3d position(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>());
      if (!position.allFinite()) throw InputError(file, "a position is not finite");
      out.positions.push_back(position);
    }
    if (out.graphs.size() != out.positions.size()) throw InputError(file, "graphs and positions differ in number");
    return out;
  } catch (const nlohmann::json::exception&) {
    spdlog::warn("{}: damaged graph cache (a field of the wrong type or missing); rebuilding it",
                 plain_error_text(file.string()));
  } catch (const InputError& e) {
    spdlog::warn("{}; rebuilding the graph cache", e.what());
  }
  return std::nullopt;
}

void write_cache(const fs::path& file, const nlohmann::json& key, const GraphSequence& sequence) {
  nlohmann::json j;
  j["key"] = key;
  j["name"] = sequence.name;
  j["graphs"] = nlohmann::json::array();
  for (const auto& g : sequence.graphs) j["graphs"].push_back(graph_to_json(g));
  j["positions"] = nlohmann::json::array();
  for (const auto& p : sequence.positions) j["positions"].push_back({p.x(), p.y(), p.z()});
  write_file_atomically(file, j.dump() + '\n');
}

}  // namespace

GraphSequence build_graph_sequence(const SourceSpec& spec, const GraphBuilderConfig& graph_config,
                                   const std::optional<fs::path>& cache_dir, bool show_progress) {
  const nlohmann::json key = {{"source", spec.to_json()}, {"graph", graph_config_json(graph_config)}};
  const fs::path cache = cache_dir ? *cache_dir / (spec.name() + ".json") : fs::path();
  if (cache_dir)
    if (auto cached = read_cache(cache, key)) return std::move(*cached);
  GraphSequence sequence = spec.kind == SourceSpec::Kind::kSimulated
                               ? simulated_graphs(spec, graph_config, show_progress)
                               : folder_graphs(spec, graph_config, show_progress);
  if (cache_dir && !stop_requested()) write_cache(cache, key, sequence);
  return sequence;
}

std::vector<TrainingPair> positive_pairs(std::span<const GraphSequence> sequences, const PairRecipe& recipe) {
  std::vector<TrainingPair> pairs;
  const double limit = recipe.positive_distance * recipe.positive_distance;
  for (std::uint32_t s = 0; s < sequences.size(); ++s) {
    const auto& p = sequences[s].positions;
    for (std::uint32_t i = 0; i < p.size(); ++i)
      for (std::uint32_t j = i + std::max<std::uint32_t>(recipe.positive_min_gap, 1); j < p.size(); ++j)
        if ((p[i] - p[j]).squaredNorm() <= limit) pairs.push_back({s, i, j, true});
  }
  return pairs;
}

std::vector<std::uint32_t> negative_candidates(const GraphSequence& sequence, std::uint32_t anchor,
                                               const PairRecipe& recipe) {
  std::vector<std::uint32_t> out;
  const double limit = recipe.negative_distance * recipe.negative_distance;
  const auto& p = sequence.positions;
  for (std::uint32_t j = 0; j < p.size(); ++j)
    if ((p[j] - p[anchor]).squaredNorm() > limit) out.push_back(j);
  return out;
}

SemanticGraph augment_graph(const SemanticGraph& graph, const AugmentOptions& options, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double yaw = (2.0 * unit(rng) - 1.0) * options.max_rotation;
  const double scale = options.scale_min + (options.scale_max - options.scale_min) * unit(rng);
  const Eigen::Vector3d shift((2.0 * unit(rng) - 1.0) * options.shift, (2.0 * unit(rng) - 1.0) * options.shift,
                              (2.0 * unit(rng) - 1.0) * 0.1 * options.shift);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  SemanticGraph out;
  for (std::size_t n = 0; n < graph.size(); ++n) {
    // Draw every random number for every node, kept or not, so that the
    // sequence of draws does not depend on the dropout outcome.
    const bool drop = unit(rng) < options.node_dropout;
    Eigen::Vector3d jitter;
    for (int a = 0; a < 3; ++a)
      jitter[a] = std::clamp(options.jitter_sigma * normal(rng), -options.jitter_clip, options.jitter_clip);
    if (drop) continue;
    out.nodes.push_back(graph.nodes[n]);
    out.centers.push_back(scale * (rotation * graph.centers[n]) + shift + jitter);
  }
  if (out.nodes.empty() && !graph.nodes.empty()) {  // never train on an empty graph made by dropout
    out.nodes.push_back(graph.nodes[0]);
    out.centers.push_back(scale * (rotation * graph.centers[0]) + shift);
  }
  return out;
}

std::vector<SgprEmbedding> embed_graphs(const SgprNetwork& network, std::span<const SemanticGraph> graphs) {
  std::vector<SgprEmbedding> out(graphs.size());
  tbb::parallel_for(std::size_t{0}, graphs.size(), [&](std::size_t i) { out[i] = network.embed(graphs[i]); });
  return out;
}

PrSummary validate_sgpr(const SgprNetwork& network, std::span<const GraphSequence> sequences,
                        const PlaceEvalConfig& protocol) {
  std::vector<double> scores;
  std::vector<std::uint8_t> truth;
  for (const auto& sequence : sequences) {
    const auto embeddings = embed_graphs(network, sequence.graphs);
    const auto pairs = place_pairs(sequence.positions, protocol);
    // Grouped by query (place_pairs orders by query): one batch per query. Logits
    // rank pairs like the scores and are better resolved near 0 and 1.
    std::size_t k = 0;
    while (k < pairs.size()) {
      const std::uint32_t query = pairs[k].query;
      std::vector<SgprEmbedding> candidates;
      const std::size_t begin = k;
      for (; k < pairs.size() && pairs[k].query == query; ++k) candidates.push_back(embeddings[pairs[k].candidate]);
      const auto logits = network.logit_batch(embeddings[query], candidates);
      for (std::size_t m = 0; m < logits.size(); ++m) {
        scores.push_back(logits[m]);
        truth.push_back(pairs[begin + m].positive ? 1 : 0);
      }
    }
  }
  return precision_recall(scores, truth);
}

}  // namespace saloam
