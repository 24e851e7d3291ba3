#pragma once
// Inference of the SGPR similarity network (Kong et al., "Semantic Graph
// Based Place Recognition for 3D Point Clouds", IROS 2020) with Eigen, in
// eval mode, following ../shared/models/sgpr/FORMAT.md layer by layer.
//
// The two graphs of a pair interact only after attention pooling, so the
// network is split in two: `embed` turns one graph into its pooled 32-vector
// (done once per scan and stored), `score` evaluates the small tensor-network
// head on two pooled vectors. `score_batch` scores one query against many
// stored embeddings at a fraction of the cost of separate calls.

#include <array>
#include <filesystem>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "saloam/place/semantic_graph.hpp"
#include "saloam/place/sgpr_weights.hpp"

namespace saloam {

inline constexpr int kSgprNodes = 100;        ///< graphs are padded (or cut) to this many nodes
inline constexpr int kSgprNeighbours = 10;    ///< k of the dynamic kNN graph (self included)
inline constexpr int kSgprEmbeddingSize = 32;
inline constexpr int kSgprTensorNeurons = 16;

/// The pooled embedding h of one graph (Sec. 5.4 of FORMAT.md).
using SgprEmbedding = Eigen::Matrix<float, kSgprEmbeddingSize, 1>;

/// Intermediate results of `embed`, for tests and inspection. Matrices are
/// channels x nodes (FORMAT.md prints them transposed, [node][channel]).
struct SgprActivations {
  Eigen::MatrixXf input;  ///< 15 x 100: xyz rows then the one-hot rows
  std::vector<std::array<int, kSgprNeighbours>> knn_xyz1;  ///< neighbours of every node in xyz layer 1
  Eigen::MatrixXf xyz1, xyz2, xyz3, sem1, sem2, sem3;
  Eigen::MatrixXf embedding;             ///< 32 x 100 (E^T)
  Eigen::VectorXf attention_context;     ///< t = tanh(g), 32
  Eigen::VectorXf attention_weights;     ///< a, 100
  SgprEmbedding pooled = SgprEmbedding::Zero();
};

/// Intermediate results of the pair head.
struct SgprPairActivations {
  Eigen::VectorXd tensor_network_out;  ///< v, 16
  Eigen::VectorXd fully_connected_out;  ///< w, 16
  double logit = 0;
  double score = 0;
};

class SgprNetwork {
 public:
  /// Takes the tensors it needs from `weights`, checking every shape; throws
  /// InputError naming `weights.source` when one is missing or misshapen.
  explicit SgprNetwork(const SgprWeights& weights);
  /// Reads a `.sgw` file (InputError when missing or malformed).
  static SgprNetwork load(const std::filesystem::path& file);

  /// The pooled embedding of a graph. Node classes must be 0..11 and centres
  /// finite within kMaxGraphCoordinate (throws std::invalid_argument
  /// otherwise). Values that overflow on the way (weights within the
  /// reader's bounds can still be too large) are an InputError naming the
  /// model's file; a NaN never leaves the network. A graph with more than 100 nodes is
  /// cut to its first 100 nodes (build_semantic_graph never makes more);
  /// fewer are padded with all-zero nodes, which take part in everything, as
  /// in the original.
  [[nodiscard]] SgprEmbedding embed(const SemanticGraph& graph, SgprActivations* activations = nullptr) const;

  /// Similarity in (0, 1) of the pair (first, second). Not symmetric: the
  /// original evaluates one given order. InputError naming the model's file
  /// when the score is not finite (as for embed; the same for the batches).
  [[nodiscard]] double score(const SgprEmbedding& first, const SgprEmbedding& second,
                             SgprPairActivations* activations = nullptr) const;
  /// The logit before the sigmoid (better resolved than the score near 0 and 1).
  [[nodiscard]] double logit(const SgprEmbedding& first, const SgprEmbedding& second) const;

  /// Logits of (query, candidate) for every candidate, the query as the first graph.
  [[nodiscard]] std::vector<double> logit_batch(const SgprEmbedding& query,
                                                std::span<const SgprEmbedding> candidates) const;
  /// Scores of (query, candidate) for every candidate, the query as the first graph.
  [[nodiscard]] std::vector<double> score_batch(const SgprEmbedding& query,
                                                std::span<const SgprEmbedding> candidates) const;

 private:
  /// One EdgeConv layer: W = [A | B] split as A and (B - A), BN folded to scale/shift.
  struct EdgeConvLayer {
    Eigen::MatrixXf diff_weight;    ///< A: C_out x C
    Eigen::MatrixXf centre_weight;  ///< B - A: C_out x C
    Eigen::VectorXf bn_scale, bn_shift;
  };
  struct Head {
    std::vector<Eigen::Matrix<double, kSgprEmbeddingSize, kSgprTensorNeurons>> bilinear;  ///< Wt[i] (32 x 16) per i
    Eigen::Matrix<double, kSgprTensorNeurons, kSgprEmbeddingSize> block_first, block_second;
    Eigen::Matrix<double, kSgprTensorNeurons, 1> bias;
    Eigen::Matrix<double, kSgprTensorNeurons, kSgprTensorNeurons> fc_weight;
    Eigen::Matrix<double, kSgprTensorNeurons, 1> fc_bias;
    Eigen::Matrix<double, 1, kSgprTensorNeurons> score_weight;
    double score_bias = 0;
  };

  static EdgeConvLayer load_edge_conv(const SgprWeights& weights, const std::string& prefix, std::uint32_t in_channels,
                                      std::uint32_t out_channels);
  static Eigen::MatrixXf edge_conv(const EdgeConvLayer& layer, const Eigen::MatrixXf& features,
                                   std::vector<std::array<int, kSgprNeighbours>>* knn_out);
  /// The three EdgeConv layers of each branch (FORMAT.md 5.2) on the input's
  /// xyz rows and one-hot rows; throws when a layer's output is not finite.
  void edge_convolutions(const Eigen::MatrixXf& input, std::array<Eigen::MatrixXf, 3>& xyz,
                         std::array<Eigen::MatrixXf, 3>& sem, SgprActivations* activations) const;
  /// Fusion (FORMAT.md 5.3): u = [p3, s3] per node, 1x1 conv + BN + LeakyReLU; 32 x N.
  [[nodiscard]] Eigen::MatrixXf fuse(const Eigen::MatrixXf& xyz, const Eigen::MatrixXf& sem) const;

  std::filesystem::path source_;  ///< the weights' file, named in errors
  std::array<EdgeConvLayer, 3> xyz_layers_, sem_layers_;
  Eigen::MatrixXf fusion_weight_;  ///< 32 x 64
  Eigen::VectorXf fusion_scale_, fusion_shift_;
  Eigen::MatrixXf attention_weight_;  ///< Wa, 32 x 32
  Head head_;
};

}  // namespace saloam
