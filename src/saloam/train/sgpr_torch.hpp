#pragma once
// SGPR (Kong et al., IROS 2020) as a libtorch module, for training. It has
// exactly the layers, parameter names and shapes of the `.sgw` format
// (../shared/models/sgpr/FORMAT.md) and computes what the Eigen inference
// (place/sgpr_network.hpp) computes, batched and differentiable:
//   embed   B graphs (B x 15 x 100 input) -> B pooled 32-vectors
//   logits  B pairs of pooled vectors -> B logits (score = sigmoid(logit))
// In train() mode the batch norms use the batch's statistics and update their
// running statistics like PyTorch's (momentum 0.1, unbiased variance); in
// eval() mode they use the running statistics, as the Eigen inference does.
//
// This header includes libtorch: only the trainer's own sources and tests
// include it, never a header used by the rest of the project.

#include <span>
#include <vector>

#include <torch/torch.h>

#include "saloam/place/semantic_graph.hpp"
#include "saloam/place/sgpr_weights.hpp"

namespace saloam {

/// One EdgeConv layer (FORMAT.md 5.1): dynamic kNN in the input's feature
/// space, 1x1 convolution of the edge features [f_j - f_i, f_i], batch norm,
/// LeakyReLU(0.2), max over the k neighbours. Submodules "0" (the Conv2d) and
/// "1" (the BatchNorm2d) give the state-dict names of the original.
class SgprEdgeConvImpl : public torch::nn::Module {
 public:
  SgprEdgeConvImpl(std::int64_t in_channels, std::int64_t out_channels);
  /// features: B x C x N -> B x C_out x N.
  torch::Tensor forward(const torch::Tensor& features);

  torch::nn::Conv2d conv{nullptr};
  torch::nn::BatchNorm2d norm{nullptr};

 private:
  std::int64_t in_channels_, out_channels_;
};
TORCH_MODULE(SgprEdgeConv);

/// Attention pooling (FORMAT.md 5.4), parameter "weight_matrix".
class SgprAttentionImpl : public torch::nn::Module {
 public:
  SgprAttentionImpl();
  /// embedding: B x N x 32 -> B x 32.
  torch::Tensor forward(const torch::Tensor& embedding);
  torch::Tensor weight_matrix;
};
TORCH_MODULE(SgprAttention);

/// The tensor network of the pair head (FORMAT.md 5.5).
class SgprTensorNetworkImpl : public torch::nn::Module {
 public:
  SgprTensorNetworkImpl();
  /// h1, h2: B x 32 -> B x 16 (after the ReLU).
  torch::Tensor forward(const torch::Tensor& h1, const torch::Tensor& h2);
  torch::Tensor weight_matrix, weight_matrix_block, bias;
};
TORCH_MODULE(SgprTensorNetwork);

class SgprTorchNetImpl : public torch::nn::Module {
 public:
  /// Fresh parameters from torch's generator (seed it with torch::manual_seed
  /// first): PyTorch's default initialisation for the convolutions and linear
  /// layers, Xavier-uniform for the attention and tensor-network matrices as
  /// in SGPR's code, batch norms at identity (gamma 1, beta 0, mean 0, var 1).
  SgprTorchNetImpl();

  /// Pooled embeddings of a batch of graphs; input B x 15 x 100 (sgpr_input).
  torch::Tensor embed(const torch::Tensor& input);
  /// Logits of the pairs (h1[b], h2[b]), graph 1 first; B x 32 each -> B.
  torch::Tensor logits(const torch::Tensor& h1, const torch::Tensor& h2);

  std::vector<SgprEdgeConv> xyz_layers, sem_layers;  // three each: dgcnn_s_conv1..3, dgcnn_f_conv1..3
  torch::nn::Sequential fusion{nullptr};  ///< dgcnn_conv_end: Conv1d(64, 32, 1) + BatchNorm1d(32)
  SgprAttention attention{nullptr};
  SgprTensorNetwork tensor_network{nullptr};
  torch::nn::Linear fully_connected_first{nullptr}, scoring_layer{nullptr};
};
TORCH_MODULE(SgprTorchNet);

/// The network input of a batch of graphs, B x 15 x 100 float: node centres
/// in rows 0..2, the one-hot class in rows 3..14, graphs cut to their first
/// 100 nodes and padded with all-zero nodes (as SgprNetwork::embed does).
/// std::invalid_argument for a class outside 0..11.
torch::Tensor sgpr_input(std::span<const SemanticGraph> graphs);
torch::Tensor sgpr_input(std::span<const SemanticGraph* const> graphs);

/// Copies every parameter and running statistic from `weights` (the 43
/// tensors of a `.sgw`), checking names and shapes: InputError naming
/// `weights.source` when one is missing or misshapen.
void load_sgpr_weights(SgprTorchNet& net, const SgprWeights& weights);
/// The network's 43 tensors as `.sgw` weights (num_batches_tracked left out, as in the format).
SgprWeights sgpr_weights_of(const SgprTorchNet& net);

}  // namespace saloam
