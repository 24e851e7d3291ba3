#include "saloam/place/sgpr_network.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace saloam {
namespace {

constexpr double kBnEpsilon = 1e-5;
constexpr float kLeakySlope = 0.2F;
constexpr int kInputRows = 3 + kNumNodeClasses;

inline float leaky_relu(float v) { return v > 0.0F ? v : kLeakySlope * v; }

/// Eval-mode BatchNorm as y * scale + shift, folded in double.
void fold_batch_norm(const SgprWeights& weights, const std::string& prefix, std::uint32_t channels,
                     Eigen::VectorXf& scale, Eigen::VectorXf& shift) {
  const auto& gamma = weights.require(prefix + ".weight", {channels}).values;
  const auto& beta = weights.require(prefix + ".bias", {channels}).values;
  const auto& mean = weights.require(prefix + ".running_mean", {channels}).values;
  const auto& var = weights.require(prefix + ".running_var", {channels}).values;
  scale.resize(channels);
  shift.resize(channels);
  for (std::uint32_t c = 0; c < channels; ++c) {
    if (var[c] < 0.0F) {
      throw InputError(weights.source, fmt::format("'{}.running_var' holds the negative variance {:g} at element {}",
                                                   prefix, var[c], c));
    }
    const double s = static_cast<double>(gamma[c]) / std::sqrt(static_cast<double>(var[c]) + kBnEpsilon);
    scale[c] = static_cast<float>(s);
    shift[c] = static_cast<float>(static_cast<double>(beta[c]) - static_cast<double>(mean[c]) * s);
  }
}

double sigmoid(double x) { return 1.0 / (1.0 + std::exp(-x)); }

/// The error for values the network could not compute: weights within the
/// reader's bounds can still overflow float32 on their way through the layers.
[[noreturn]] void overflowed(const std::filesystem::path& source, std::string_view where) {
  throw InputError(source, fmt::format("the SGPR network overflows ({} is not finite): the model's weights are too "
                                       "large to be a trained model",
                                       where));
}

}  // namespace

SgprNetwork::EdgeConvLayer SgprNetwork::load_edge_conv(const SgprWeights& weights, const std::string& prefix,
                                                       std::uint32_t in_channels, std::uint32_t out_channels) {
  const auto& w = weights.require(prefix + ".0.weight", {out_channels, 2 * in_channels, 1, 1}).values;
  EdgeConvLayer layer;
  layer.diff_weight.resize(out_channels, in_channels);
  layer.centre_weight.resize(out_channels, in_channels);
  for (std::uint32_t o = 0; o < out_channels; ++o) {
    for (std::uint32_t c = 0; c < in_channels; ++c) {
      const float a = w[o * 2 * in_channels + c];
      const float b = w[o * 2 * in_channels + in_channels + c];
      layer.diff_weight(o, c) = a;
      // y_ij = A (f_j - f_i) + B f_i = A f_j + (B - A) f_i (FORMAT.md 5.1).
      layer.centre_weight(o, c) = b - a;
    }
  }
  fold_batch_norm(weights, prefix + ".1", out_channels, layer.bn_scale, layer.bn_shift);
  return layer;
}

SgprNetwork::SgprNetwork(const SgprWeights& weights) : source_(weights.source) {
  constexpr std::array<std::uint32_t, 3> kIn{0, 64, 64};  // layer 1 input depends on the branch
  constexpr std::array<std::uint32_t, 3> kOut{64, 64, 32};
  for (int l = 0; l < 3; ++l) {
    const std::string n = std::to_string(l + 1);
    xyz_layers_[l] = load_edge_conv(weights, "dgcnn_s_conv" + n, l == 0 ? 3U : kIn[l], kOut[l]);
    sem_layers_[l] = load_edge_conv(weights, "dgcnn_f_conv" + n, l == 0 ? 12U : kIn[l], kOut[l]);
  }
  const auto& end = weights.require("dgcnn_conv_end.0.weight", {32, 64, 1}).values;
  fusion_weight_ = Eigen::Map<const Eigen::Matrix<float, 32, 64, Eigen::RowMajor>>(end.data());
  fold_batch_norm(weights, "dgcnn_conv_end.1", 32, fusion_scale_, fusion_shift_);
  const auto& wa = weights.require("attention.weight_matrix", {32, 32}).values;
  attention_weight_ = Eigen::Map<const Eigen::Matrix<float, 32, 32, Eigen::RowMajor>>(wa.data());

  const auto& wt = weights.require("tensor_network.weight_matrix", {32, 32, 16}).values;
  head_.bilinear.resize(kSgprEmbeddingSize);
  for (int i = 0; i < kSgprEmbeddingSize; ++i)
    for (int j = 0; j < kSgprEmbeddingSize; ++j)
      for (int k = 0; k < kSgprTensorNeurons; ++k)
        head_.bilinear[i](j, k) = wt[(i * kSgprEmbeddingSize + j) * kSgprTensorNeurons + k];
  const auto& wb = weights.require("tensor_network.weight_matrix_block", {16, 64}).values;
  for (int k = 0; k < kSgprTensorNeurons; ++k)
    for (int c = 0; c < kSgprEmbeddingSize; ++c) {
      head_.block_first(k, c) = wb[k * 64 + c];
      head_.block_second(k, c) = wb[k * 64 + 32 + c];
    }
  const auto& bt = weights.require("tensor_network.bias", {16, 1}).values;
  const auto& fw = weights.require("fully_connected_first.weight", {16, 16}).values;
  const auto& fb = weights.require("fully_connected_first.bias", {16}).values;
  const auto& sw = weights.require("scoring_layer.weight", {1, 16}).values;
  const auto& sb = weights.require("scoring_layer.bias", {1}).values;
  for (int k = 0; k < kSgprTensorNeurons; ++k) {
    head_.bias(k) = bt[k];
    head_.fc_bias(k) = fb[k];
    head_.score_weight(k) = sw[k];
    for (int m = 0; m < kSgprTensorNeurons; ++m) head_.fc_weight(k, m) = fw[k * 16 + m];
  }
  head_.score_bias = sb[0];
}

SgprNetwork SgprNetwork::load(const std::filesystem::path& file) { return SgprNetwork(read_sgpr_weights(file)); }

Eigen::MatrixXf SgprNetwork::edge_conv(const EdgeConvLayer& layer, const Eigen::MatrixXf& features,
                                       std::vector<std::array<int, kSgprNeighbours>>* knn_out) {
  const int n = static_cast<int>(features.cols());
  // Squared distances in double via the Gram matrix: accurate enough that the
  // neighbour sets equal those of a direct float64 computation (FORMAT.md 5.1).
  const Eigen::MatrixXd f = features.cast<double>();
  const Eigen::MatrixXd gram = f.transpose() * f;
  const Eigen::VectorXd norms = gram.diagonal();

  const Eigen::MatrixXf diff_term = layer.diff_weight * features;      // A f_j
  const Eigen::MatrixXf centre_term = layer.centre_weight * features;  // (B - A) f_i
  const int out_channels = static_cast<int>(diff_term.rows());
  Eigen::MatrixXf out(out_channels, n);
  if (knn_out) knn_out->assign(static_cast<std::size_t>(n), {});

  std::vector<int> order(static_cast<std::size_t>(n));
  std::vector<double> distance(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) distance[j] = norms[i] + norms[j] - 2.0 * gram(j, i);
    distance[i] = 0.0;  // exact self-distance; the node is always a candidate
    std::iota(order.begin(), order.end(), 0);
    // The k nearest, self included; ties broken by index so the result is deterministic.
    std::nth_element(order.begin(), order.begin() + (kSgprNeighbours - 1), order.end(), [&](int a, int b) {
      return distance[a] < distance[b] || (distance[a] == distance[b] && a < b);
    });
    if (knn_out) std::copy_n(order.begin(), kSgprNeighbours, (*knn_out)[i].begin());
    for (int c = 0; c < out_channels; ++c) {
      const float centre = centre_term(c, i);
      float best = -std::numeric_limits<float>::infinity();
      for (int m = 0; m < kSgprNeighbours; ++m) {
        // BN and LeakyReLU per edge, then the max over the neighbours.
        const float z = leaky_relu((diff_term(c, order[m]) + centre) * layer.bn_scale[c] + layer.bn_shift[c]);
        best = std::max(best, z);
      }
      out(c, i) = best;
    }
  }
  return out;
}

namespace {

/// The network's input (FORMAT.md 4): per node its centre [m] (rows 0-2)
/// and its one-hot class (rows 3-14), for the first kSgprNodes nodes. Padding
/// nodes stay all zero (position 0 and no class) and take part in everything.
Eigen::MatrixXf network_input(const SemanticGraph& graph) {
  if (graph.centers.size() != graph.nodes.size())
    throw std::invalid_argument("SGPR: graph has " + std::to_string(graph.nodes.size()) + " node classes but " +
                                std::to_string(graph.centers.size()) + " centres");
  Eigen::MatrixXf input = Eigen::MatrixXf::Zero(kInputRows, kSgprNodes);
  const int used = static_cast<int>(std::min<std::size_t>(graph.size(), kSgprNodes));
  for (int n = 0; n < used; ++n) {
    const int label = graph.nodes[n];
    if (label < 0 || label >= kNumNodeClasses)
      throw std::invalid_argument("SGPR: node " + std::to_string(n) + " has class " + std::to_string(label) +
                                  " (expected 0..11)");
    const Eigen::Vector3d& centre = graph.centers[n];
    if (!centre.allFinite() || centre.cwiseAbs().maxCoeff() > kMaxGraphCoordinate)
      throw std::invalid_argument("SGPR: node " + std::to_string(n) + " has a centre that is not finite or beyond " +
                                  std::to_string(static_cast<int>(kMaxGraphCoordinate)) + " m");
    input.block<3, 1>(0, n) = centre.cast<float>();
    input(3 + label, n) = 1.0F;
  }
  return input;
}

struct AttentionPooling {
  Eigen::VectorXf context;    ///< t = tanh(g)
  Eigen::VectorXf attention;  ///< a_n per node
  SgprEmbedding pooled;       ///< h
};

/// Attention pooling (FORMAT.md 5.4) of the 32 x N node embeddings E:
/// g = mean_n(E_n Wa), t = tanh(g), a_n = sigmoid(E_n . t), h = sum_n a_n E_n
/// (a weighted sum, padding included).
AttentionPooling attention_pool(const Eigen::MatrixXf& embedding, const Eigen::MatrixXf& attention_weight) {
  AttentionPooling out;
  const Eigen::VectorXf mean = embedding.rowwise().sum() / static_cast<float>(kSgprNodes);
  out.context = (attention_weight.transpose() * mean).array().tanh();
  out.attention = (embedding.transpose() * out.context).unaryExpr([](float v) { return 1.0F / (1.0F + std::exp(-v)); });
  out.pooled = embedding * out.attention;
  return out;
}

}  // namespace

void SgprNetwork::edge_convolutions(const Eigen::MatrixXf& input, std::array<Eigen::MatrixXf, 3>& xyz,
                                    std::array<Eigen::MatrixXf, 3>& sem, SgprActivations* activations) const {
  const Eigen::MatrixXf p = input.topRows(3);
  const Eigen::MatrixXf s = input.bottomRows(kNumNodeClasses);
  for (int l = 0; l < 3; ++l) {
    xyz[l] = edge_conv(xyz_layers_[l], l == 0 ? p : xyz[l - 1],
                       (activations && l == 0) ? &activations->knn_xyz1 : nullptr);
    sem[l] = edge_conv(sem_layers_[l], l == 0 ? s : sem[l - 1], nullptr);
    // A non-finite feature would reach the next layer's neighbour search
    // (NaN distances break its ordering): stop here.
    if (!xyz[l].allFinite() || !sem[l].allFinite()) {
      overflowed(source_, fmt::format("the output of edge convolution {}", l + 1));
    }
  }
}

Eigen::MatrixXf SgprNetwork::fuse(const Eigen::MatrixXf& xyz, const Eigen::MatrixXf& sem) const {
  Eigen::MatrixXf fused(64, kSgprNodes);
  fused.topRows(32) = xyz;
  fused.bottomRows(32) = sem;
  Eigen::MatrixXf embedding = fusion_weight_ * fused;  // 32 x N
  for (int n = 0; n < kSgprNodes; ++n)
    for (int c = 0; c < 32; ++c) embedding(c, n) = leaky_relu(embedding(c, n) * fusion_scale_[c] + fusion_shift_[c]);
  return embedding;
}

SgprEmbedding SgprNetwork::embed(const SemanticGraph& graph, SgprActivations* activations) const {
  const Eigen::MatrixXf input = network_input(graph);
  std::array<Eigen::MatrixXf, 3> xyz, sem;
  edge_convolutions(input, xyz, sem, activations);
  const Eigen::MatrixXf embedding = fuse(xyz[2], sem[2]);
  AttentionPooling pooling = attention_pool(embedding, attention_weight_);
  if (!pooling.pooled.allFinite()) overflowed(source_, "the pooled embedding");
  if (activations) {
    activations->input = input;
    activations->xyz1 = xyz[0];
    activations->xyz2 = xyz[1];
    activations->xyz3 = xyz[2];
    activations->sem1 = sem[0];
    activations->sem2 = sem[1];
    activations->sem3 = sem[2];
    activations->embedding = embedding;
    activations->attention_context = pooling.context;
    activations->attention_weights = pooling.attention;
    activations->pooled = pooling.pooled;
  }
  return pooling.pooled;
}

double SgprNetwork::score(const SgprEmbedding& first, const SgprEmbedding& second,
                          SgprPairActivations* activations) const {
  const Eigen::Matrix<double, kSgprEmbeddingSize, 1> h1 = first.cast<double>();
  const Eigen::Matrix<double, kSgprEmbeddingSize, 1> h2 = second.cast<double>();
  // Tensor network (FORMAT.md 5.5): bilinear[k] = h1^T Wt[:,:,k] h2, plus the block term and bias.
  Eigen::Matrix<double, kSgprTensorNeurons, 1> bilinear = Eigen::Matrix<double, kSgprTensorNeurons, 1>::Zero();
  for (int i = 0; i < kSgprEmbeddingSize; ++i) bilinear += h1[i] * (head_.bilinear[i].transpose() * h2);
  const Eigen::Matrix<double, kSgprTensorNeurons, 1> v =
      (bilinear + head_.block_first * h1 + head_.block_second * h2 + head_.bias).cwiseMax(0.0);
  const Eigen::Matrix<double, kSgprTensorNeurons, 1> w = (head_.fc_weight * v + head_.fc_bias).cwiseMax(0.0);
  const double logit = head_.score_weight.dot(w.transpose()) + head_.score_bias;
  if (!std::isfinite(logit)) overflowed(source_, "the score");
  const double result = sigmoid(logit);
  if (activations) {
    activations->tensor_network_out = v;
    activations->fully_connected_out = w;
    activations->logit = logit;
    activations->score = result;
  }
  return result;
}

double SgprNetwork::logit(const SgprEmbedding& first, const SgprEmbedding& second) const {
  SgprPairActivations a;
  (void)score(first, second, &a);
  return a.logit;
}

std::vector<double> SgprNetwork::logit_batch(const SgprEmbedding& query,
                                             std::span<const SgprEmbedding> candidates) const {
  const Eigen::Matrix<double, kSgprEmbeddingSize, 1> h1 = query.cast<double>();
  // Fold everything that depends on the query alone into one 16 x 32 matrix and
  // a 16-vector: v = relu(Q h2 + c) with Q = sum_i h1[i] Wt[i]^T + Wb2.
  Eigen::Matrix<double, kSgprTensorNeurons, kSgprEmbeddingSize> q = head_.block_second;
  for (int i = 0; i < kSgprEmbeddingSize; ++i) q += h1[i] * head_.bilinear[i].transpose();
  const Eigen::Matrix<double, kSgprTensorNeurons, 1> c = head_.block_first * h1 + head_.bias;

  std::vector<double> logits(candidates.size());
  constexpr std::size_t kChunk = 64;
  Eigen::Matrix<double, kSgprEmbeddingSize, Eigen::Dynamic> h2(kSgprEmbeddingSize, kChunk);
  for (std::size_t start = 0; start < candidates.size(); start += kChunk) {
    const std::size_t count = std::min(kChunk, candidates.size() - start);
    h2.resize(kSgprEmbeddingSize, static_cast<Eigen::Index>(count));
    for (std::size_t m = 0; m < count; ++m) h2.col(static_cast<Eigen::Index>(m)) = candidates[start + m].cast<double>();
    const Eigen::MatrixXd v = ((q * h2).colwise() + c).cwiseMax(0.0);
    const Eigen::MatrixXd w = ((head_.fc_weight * v).colwise() + head_.fc_bias).cwiseMax(0.0);
    const Eigen::RowVectorXd l = (head_.score_weight * w).array() + head_.score_bias;
    if (!l.allFinite()) overflowed(source_, "a score");
    for (std::size_t m = 0; m < count; ++m) logits[start + m] = l[static_cast<Eigen::Index>(m)];
  }
  return logits;
}

std::vector<double> SgprNetwork::score_batch(const SgprEmbedding& query,
                                             std::span<const SgprEmbedding> candidates) const {
  auto values = logit_batch(query, candidates);
  for (double& v : values) v = sigmoid(v);
  return values;
}

}  // namespace saloam
