#pragma once
// Training data for SGPR (Kong et al., IROS 2020, Sec. IV-A): semantic graphs
// of scans with ground-truth positions, grouped by sequence, built from
//   - simulated sequences along a trajectory (rendered in memory, never
//     written to disk), or
//   - sequence folders in the SemanticKITTI layout (velodyne/, labels/,
//     poses.txt, calib.txt),
// every k-th frame. A data recipe (YAML) lists the training and validation
// sources; validation comes from separate sequences. Pairs follow SGPR:
// positive within 3 m, negative beyond 20 m, within one sequence.
// No libtorch here.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "saloam/place/place_recognition.hpp"
#include "saloam/place/semantic_graph.hpp"
#include "saloam/place/sgpr_network.hpp"
#include "saloam/train/data_recipe.hpp"

namespace saloam {

/// The graphs of one sequence and where each scan was taken (LiDAR position
/// in the sequence's world frame).
struct GraphSequence {
  std::string name;
  std::vector<SemanticGraph> graphs;
  std::vector<Eigen::Vector3d> positions;
};

/// Builds (in parallel) the graphs of a source. With `cache_dir`, the result
/// is stored there as <name>.json and reused when the source and the graph
/// recipe are unchanged. InputError for missing poses, labels or calibration.
/// Stops early (returning what it has, marked incomplete) on stop_requested().
GraphSequence build_graph_sequence(const SourceSpec& spec, const GraphBuilderConfig& graph_config,
                                   const std::optional<std::filesystem::path>& cache_dir, bool show_progress);

/// One training pair of graphs of one sequence.
struct TrainingPair {
  std::uint32_t sequence = 0, first = 0, second = 0;
  bool positive = false;
};

struct PairRecipe {
  double positive_distance = 3.0;   ///< [m] SGPR: positives within 3 m
  double negative_distance = 20.0;  ///< [m] negatives beyond 20 m
  /// Positives are at least this many frames apart in their sequence (SGPR:
  /// 0, every pair). Pairs closer in the sequence are mostly scans taken
  /// while the car stood or crept (near copies of one scan); a gap like the
  /// evaluation's recent-frame exclusion keeps only revisits, the pairs a
  /// loop detector has to find.
  std::uint32_t positive_min_gap = 0;
};

/// Every positive pair (i < j) of every sequence.
std::vector<TrainingPair> positive_pairs(std::span<const GraphSequence> sequences, const PairRecipe& recipe);
/// Indices of the frames of `sequence` beyond the negative distance from frame `anchor`.
std::vector<std::uint32_t> negative_candidates(const GraphSequence& sequence, std::uint32_t anchor,
                                               const PairRecipe& recipe);

/// Augmentations of a graph (SGPR's: rotation about z, jitter, scale, shift;
/// plus node dropout), applied to the real nodes only: padding stays at the
/// origin as in inference. Rotation about z makes the embedding learn that a
/// place seen in the other direction is the same place.
struct AugmentOptions {
  double max_rotation = 3.14159265358979323846;  ///< [rad] yaw uniform in [-max, max]
  double jitter_sigma = 0.1;   ///< [m] per-node Gaussian jitter of the centre
  double jitter_clip = 0.3;    ///< [m]
  double scale_min = 0.95, scale_max = 1.05;
  double shift = 1.0;          ///< [m] whole-graph shift, uniform per axis in x, y (z: a tenth)
  double node_dropout = 0.1;   ///< probability of dropping each node
};
SemanticGraph augment_graph(const SemanticGraph& graph, const AugmentOptions& options, std::mt19937_64& rng);

/// Embeddings of many graphs with the Eigen inference (in parallel).
std::vector<SgprEmbedding> embed_graphs(const SgprNetwork& network, std::span<const SemanticGraph> graphs);

/// Place-recognition metrics of `network` on the sequences with SGPR's
/// protocol (all pairs, `protocol`'s distances and recent-frame exclusion),
/// pooled over the sequences.
PrSummary validate_sgpr(const SgprNetwork& network, std::span<const GraphSequence> sequences,
                        const PlaceEvalConfig& protocol);

}  // namespace saloam
