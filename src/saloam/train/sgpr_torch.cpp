#include "saloam/train/sgpr_torch.hpp"

#include <stdexcept>
#include <string>

#include "saloam/core/error.hpp"
#include "saloam/place/sgpr_network.hpp"

namespace saloam {
namespace {

constexpr double kLeakySlope = 0.2;
constexpr std::int64_t kInputRows = 3 + kNumNodeClasses;

/// Indices of the k nearest nodes of every node, itself included (B x N x k).
/// Squared distances in double, the self-distance exactly 0, as in the Eigen
/// inference: the neighbour sets then agree with it (FORMAT.md 5.1). No
/// gradient flows through the choice of neighbours, as in the original.
torch::Tensor nearest_neighbours(const torch::Tensor& features) {
  const torch::NoGradGuard no_grad;
  const torch::Tensor f = features.to(torch::kDouble);       // B x C x N
  const torch::Tensor gram = torch::bmm(f.transpose(1, 2), f);  // B x N x N
  const torch::Tensor norms = gram.diagonal(0, 1, 2);          // B x N
  torch::Tensor distance = norms.unsqueeze(2) + norms.unsqueeze(1) - 2.0 * gram;
  distance.diagonal(0, 1, 2).zero_();
  return std::get<1>(distance.topk(kSgprNeighbours, /*dim=*/2, /*largest=*/false, /*sorted=*/true));
}

}  // namespace

SgprEdgeConvImpl::SgprEdgeConvImpl(std::int64_t in_channels, std::int64_t out_channels)
    : in_channels_(in_channels), out_channels_(out_channels) {
  conv = register_module("0", torch::nn::Conv2d(torch::nn::Conv2dOptions(2 * in_channels, out_channels, 1).bias(false)));
  norm = register_module("1", torch::nn::BatchNorm2d(torch::nn::BatchNorm2dOptions(out_channels).eps(1e-5).momentum(0.1)));
}

torch::Tensor SgprEdgeConvImpl::forward(const torch::Tensor& features) {
  const std::int64_t batch = features.size(0), nodes = features.size(2);
  const torch::Tensor index = nearest_neighbours(features);  // B x N x k
  // W = [A | B] on [f_j - f_i, f_i]: y_ij = A f_j + (B - A) f_i. Computing
  // A f and (B - A) f per node and adding per edge gives the same edge values
  // (and gradients) as convolving the 2C-channel edge tensor, at half the cost.
  const torch::Tensor w = conv->weight.view({out_channels_, 2 * in_channels_});
  const torch::Tensor a = w.narrow(1, 0, in_channels_);
  const torch::Tensor centre_weight = w.narrow(1, in_channels_, in_channels_) - a;
  const torch::Tensor neighbour_term = torch::matmul(a, features);     // B x C_out x N
  const torch::Tensor centre_term = torch::matmul(centre_weight, features);
  const torch::Tensor flat = index.reshape({batch, 1, nodes * kSgprNeighbours}).expand({batch, out_channels_, -1});
  const torch::Tensor edges =
      neighbour_term.gather(2, flat).view({batch, out_channels_, nodes, kSgprNeighbours}) + centre_term.unsqueeze(3);
  // Batch norm per edge (train mode: statistics over batch, nodes and neighbours, as BatchNorm2d in the original).
  const torch::Tensor z = torch::leaky_relu(norm(edges), kLeakySlope);
  return std::get<0>(z.max(3));
}

SgprAttentionImpl::SgprAttentionImpl() {
  weight_matrix = register_parameter("weight_matrix", torch::empty({kSgprEmbeddingSize, kSgprEmbeddingSize}));
  torch::nn::init::xavier_uniform_(weight_matrix);
}

torch::Tensor SgprAttentionImpl::forward(const torch::Tensor& embedding) {
  // g = mean_n(E_n Wa), t = tanh(g), a_n = sigmoid(E_n . t), h = sum_n a_n E_n.
  const torch::Tensor context = torch::tanh(torch::matmul(embedding, weight_matrix).mean(1));  // B x 32
  const torch::Tensor weights = torch::sigmoid(torch::bmm(embedding, context.unsqueeze(2)));  // B x N x 1
  return torch::bmm(embedding.transpose(1, 2), weights).squeeze(2);                          // B x 32
}

SgprTensorNetworkImpl::SgprTensorNetworkImpl() {
  weight_matrix = register_parameter(
      "weight_matrix", torch::empty({kSgprEmbeddingSize, kSgprEmbeddingSize, kSgprTensorNeurons}));
  weight_matrix_block =
      register_parameter("weight_matrix_block", torch::empty({kSgprTensorNeurons, 2 * kSgprEmbeddingSize}));
  bias = register_parameter("bias", torch::empty({kSgprTensorNeurons, 1}));
  torch::nn::init::xavier_uniform_(weight_matrix);
  torch::nn::init::xavier_uniform_(weight_matrix_block);
  torch::nn::init::xavier_uniform_(bias);
}

torch::Tensor SgprTensorNetworkImpl::forward(const torch::Tensor& h1, const torch::Tensor& h2) {
  const torch::Tensor bilinear = torch::einsum("bi,ijk,bj->bk", {h1, weight_matrix, h2});
  const torch::Tensor block = torch::matmul(torch::cat({h1, h2}, 1), weight_matrix_block.t());
  return torch::relu(bilinear + block + bias.view({1, kSgprTensorNeurons}));
}

SgprTorchNetImpl::SgprTorchNetImpl() {
  // Registered in the state-dict order of the original (FORMAT.md 3).
  attention = register_module("attention", SgprAttention());
  tensor_network = register_module("tensor_network", SgprTensorNetwork());
  fully_connected_first =
      register_module("fully_connected_first", torch::nn::Linear(kSgprTensorNeurons, kSgprTensorNeurons));
  scoring_layer = register_module("scoring_layer", torch::nn::Linear(kSgprTensorNeurons, 1));
  const std::array<std::int64_t, 3> xyz_in{3, 64, 64}, sem_in{kNumNodeClasses, 64, 64}, out{64, 64, 32};
  for (int l = 0; l < 3; ++l) {
    const std::string n = std::to_string(l + 1);
    xyz_layers.push_back(register_module("dgcnn_s_conv" + n, SgprEdgeConv(xyz_in[l], out[l])));
    sem_layers.push_back(register_module("dgcnn_f_conv" + n, SgprEdgeConv(sem_in[l], out[l])));
  }
  fusion = register_module(
      "dgcnn_conv_end",
      torch::nn::Sequential(torch::nn::Conv1d(torch::nn::Conv1dOptions(64, kSgprEmbeddingSize, 1).bias(false)),
                            torch::nn::BatchNorm1d(torch::nn::BatchNorm1dOptions(kSgprEmbeddingSize).eps(1e-5))));
}

torch::Tensor SgprTorchNetImpl::embed(const torch::Tensor& input) {
  torch::Tensor xyz = input.narrow(1, 0, 3);
  torch::Tensor sem = input.narrow(1, 3, kNumNodeClasses);
  for (int l = 0; l < 3; ++l) {
    xyz = xyz_layers[l]->forward(xyz);
    sem = sem_layers[l]->forward(sem);
  }
  const torch::Tensor fused = torch::leaky_relu(fusion->forward(torch::cat({xyz, sem}, 1)), kLeakySlope);  // B x 32 x N
  return attention->forward(fused.transpose(1, 2));
}

torch::Tensor SgprTorchNetImpl::logits(const torch::Tensor& h1, const torch::Tensor& h2) {
  const torch::Tensor v = tensor_network->forward(h1, h2);
  const torch::Tensor w = torch::relu(fully_connected_first->forward(v));
  return scoring_layer->forward(w).squeeze(1);
}

namespace {

template <class GraphAt>
torch::Tensor input_of(std::size_t count, GraphAt&& graph_at) {
  torch::Tensor input = torch::zeros({static_cast<std::int64_t>(count), kInputRows, kSgprNodes});
  auto x = input.accessor<float, 3>();
  for (std::size_t b = 0; b < count; ++b) {
    const SemanticGraph& graph = graph_at(b);
    if (graph.centers.size() != graph.nodes.size())
      throw std::invalid_argument("SGPR: graph has " + std::to_string(graph.nodes.size()) + " node classes but " +
                                  std::to_string(graph.centers.size()) + " centres");
    const std::size_t used = std::min<std::size_t>(graph.size(), kSgprNodes);
    for (std::size_t n = 0; n < used; ++n) {
      const int label = graph.nodes[n];
      if (label < 0 || label >= kNumNodeClasses)
        throw std::invalid_argument("SGPR: node " + std::to_string(n) + " has class " + std::to_string(label) +
                                    " (expected 0..11)");
      for (int r = 0; r < 3; ++r) x[b][r][n] = static_cast<float>(graph.centers[n][r]);
      x[b][3 + label][n] = 1.0F;
    }
  }
  return input;
}

/// Every tensor of the state dict that the `.sgw` format holds.
std::vector<std::pair<std::string, torch::Tensor>> sgw_tensors(const SgprTorchNet& net) {
  std::vector<std::pair<std::string, torch::Tensor>> out;
  for (const auto& p : net->named_parameters()) out.emplace_back(p.key(), p.value());
  for (const auto& b : net->named_buffers())
    if (b.key().find("num_batches_tracked") == std::string::npos) out.emplace_back(b.key(), b.value());
  return out;
}

}  // namespace

torch::Tensor sgpr_input(std::span<const SemanticGraph> graphs) {
  return input_of(graphs.size(), [&](std::size_t b) -> const SemanticGraph& { return graphs[b]; });
}

torch::Tensor sgpr_input(std::span<const SemanticGraph* const> graphs) {
  return input_of(graphs.size(), [&](std::size_t b) -> const SemanticGraph& { return *graphs[b]; });
}

void load_sgpr_weights(SgprTorchNet& net, const SgprWeights& weights) {
  const torch::NoGradGuard no_grad;
  for (auto& [name, tensor] : sgw_tensors(net)) {
    std::vector<std::uint32_t> dims;
    for (const auto d : tensor.sizes()) dims.push_back(static_cast<std::uint32_t>(d));
    const SgprTensor& source = weights.require(name, dims);
    tensor.copy_(torch::from_blob(const_cast<float*>(source.values.data()), tensor.sizes(), torch::kFloat));
  }
}

SgprWeights sgpr_weights_of(const SgprTorchNet& net) {
  SgprWeights weights;
  for (const auto& [name, tensor] : sgw_tensors(net)) {
    const torch::Tensor t = tensor.detach().contiguous().to(torch::kFloat);
    SgprTensor out;
    for (const auto d : t.sizes()) out.dims.push_back(static_cast<std::uint32_t>(d));
    out.values.assign(t.data_ptr<float>(), t.data_ptr<float>() + t.numel());
    weights.tensors.emplace(name, std::move(out));
  }
  return weights;
}

}  // namespace saloam
