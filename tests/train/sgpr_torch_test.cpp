// The libtorch SGPR module against the Eigen inference: same weights, same
// graphs, same scores (so training and inference cannot drift apart), and
// the .sgw round trip through the module.

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "saloam/place/graph_json.hpp"
#include "saloam/place/sgpr_network.hpp"
#include "saloam/train/sgpr_torch.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

/// Random graphs of 20..85 nodes (at most 90, so the semantic branch has no
/// ties between different feature vectors, FORMAT.md 5.1), centres within 40 m.
std::vector<SemanticGraph> random_graphs(int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> size(20, 85), label(0, kNumNodeClasses - 1);
  std::uniform_real_distribution<double> xy(-40.0, 40.0), z(-2.0, 4.0);
  std::vector<SemanticGraph> graphs(count);
  for (auto& g : graphs) {
    const int n = size(rng);
    for (int i = 0; i < n; ++i) {
      g.nodes.push_back(label(rng));
      g.centers.emplace_back(xy(rng), xy(rng), z(rng));
    }
  }
  return graphs;
}

/// Batch norms away from identity (negative gammas too), so eval mode is really exercised.
void randomise_batch_norms(SgprTorchNet& net, std::uint64_t seed) {
  torch::manual_seed(seed);
  const torch::NoGradGuard no_grad;
  for (auto& p : net->named_parameters())
    if (p.key().find(".1.weight") != std::string::npos) p.value().copy_(torch::randn_like(p.value()));
    else if (p.key().find(".1.bias") != std::string::npos) p.value().copy_(0.5 * torch::randn_like(p.value()));
  for (auto& b : net->named_buffers())
    if (b.key().find("running_mean") != std::string::npos) b.value().copy_(torch::randn_like(b.value()));
    else if (b.key().find("running_var") != std::string::npos) b.value().copy_(0.5 + torch::rand_like(b.value()));
}

struct Comparison {
  double max_score_error = 0, max_logit_error = 0, max_pooled_error = 0;  ///< pooled: relative to the largest |h|
};

Comparison compare(SgprTorchNet& net, const SgprNetwork& eigen, const std::vector<SemanticGraph>& graphs) {
  const torch::NoGradGuard no_grad;
  net->eval();
  const torch::Tensor h = net->embed(sgpr_input(graphs));
  Comparison c;
  std::vector<SgprEmbedding> e;
  for (std::size_t i = 0; i < graphs.size(); ++i) {
    e.push_back(eigen.embed(graphs[i]));
    const auto row = h[static_cast<std::int64_t>(i)];
    const double scale = std::max(1.0, static_cast<double>(e.back().cwiseAbs().maxCoeff()));
    for (int k = 0; k < kSgprEmbeddingSize; ++k)
      c.max_pooled_error = std::max(c.max_pooled_error, std::abs(row[k].item<double>() - e.back()[k]) / scale);
  }
  const auto n = static_cast<std::int64_t>(graphs.size());
  for (std::int64_t i = 0; i < n; ++i) {
    const torch::Tensor first = h[i].unsqueeze(0).expand({n, kSgprEmbeddingSize});
    const torch::Tensor logits = net->logits(first, h);
    for (std::int64_t j = 0; j < n; ++j) {
      const double t = logits[j].item<double>();
      c.max_logit_error = std::max(c.max_logit_error, std::abs(t - eigen.logit(e[i], e[j])));
      c.max_score_error = std::max(c.max_score_error, std::abs(1.0 / (1.0 + std::exp(-t)) - eigen.score(e[i], e[j])));
    }
  }
  return c;
}

TEST(SgprTorch, AgreesWithEigenOnRandomWeightsAndSyntheticGraphs) {
  torch::manual_seed(3);
  SgprTorchNet net;
  randomise_batch_norms(net, 4);
  const SgprNetwork eigen(sgpr_weights_of(net));
  const auto c = compare(net, eigen, random_graphs(12, 5));
  EXPECT_LT(c.max_score_error, 1e-5);
  EXPECT_LT(c.max_logit_error, 1e-3);
  EXPECT_LT(c.max_pooled_error, 1e-5);
}

TEST(SgprTorch, AgreesWithEigenOnTheKittiModel) {
  SALOAM_REQUIRE_SHARED_DATA();
  SgprTorchNet net;
  load_sgpr_weights(net, read_sgpr_weights(testing::shared_file("models/sgpr/sgpr_kitti.sgw")));
  const SgprNetwork eigen = SgprNetwork::load(testing::shared_file("models/sgpr/sgpr_kitti.sgw"));
  std::vector<SemanticGraph> graphs;
  for (const char* id : {"0", "3", "250"})
    graphs.push_back(read_graph_json(testing::shared_file(std::string("models/sgpr/graph_") + id + ".json")));
  const auto c = compare(net, eigen, graphs);
  EXPECT_LT(c.max_score_error, 1e-5);
  EXPECT_LT(c.max_logit_error, 1e-3);
  EXPECT_LT(c.max_pooled_error, 1e-5);
  // And the reference score of the original for the true match 0-3 (FORMAT.md 6).
  const torch::NoGradGuard no_grad;
  const torch::Tensor h = net->embed(sgpr_input(graphs));
  const double score = torch::sigmoid(net->logits(h.narrow(0, 0, 1), h.narrow(0, 1, 1)))[0].item<double>();
  EXPECT_NEAR(score, 0.997977436, 1e-5);
}

TEST(SgprTorch, SgwRoundTripThroughTheModuleIsBitExact) {
  testing::TempDir dir;
  torch::manual_seed(11);
  SgprTorchNet net;
  randomise_batch_norms(net, 12);
  const SgprWeights weights = sgpr_weights_of(net);
  EXPECT_EQ(weights.tensors.size(), 43U);  // num_batches_tracked is not part of the format
  write_sgpr_weights(dir / "model.sgw", weights);
  SgprTorchNet other;
  load_sgpr_weights(other, read_sgpr_weights(dir / "model.sgw"));
  const SgprWeights again = sgpr_weights_of(other);
  for (const auto& [name, t] : weights.tensors) {
    const auto& u = again.tensors.at(name);
    EXPECT_EQ(u.dims, t.dims) << name;
    ASSERT_EQ(u.values.size(), t.values.size());
    EXPECT_EQ(std::memcmp(u.values.data(), t.values.data(), 4 * t.values.size()), 0) << name;
  }
  // Weights lacking a tensor are refused with the file named.
  SgprWeights partial = weights;
  partial.source = "partial.sgw";
  partial.tensors.erase("attention.weight_matrix");
  EXPECT_NE(testing::input_error_of([&] { load_sgpr_weights(other, partial); }).find("partial.sgw"), std::string::npos);
}

TEST(SgprTorch, TrainModeUpdatesRunningStatisticsAndEvalModeDoesNot) {
  torch::manual_seed(21);
  SgprTorchNet net;
  const auto graphs = random_graphs(4, 22);
  const auto running_mean = [&] { return net->xyz_layers[0]->norm->running_mean.clone(); };
  const torch::Tensor before = running_mean();
  {
    const torch::NoGradGuard no_grad;
    net->eval();
    (void)net->embed(sgpr_input(graphs));
  }
  EXPECT_TRUE(torch::equal(before, running_mean()));
  net->train();
  (void)net->embed(sgpr_input(graphs));
  // PyTorch's update with momentum 0.1 from a zero mean: 0.1 x the batch mean, not zero.
  EXPECT_GT(running_mean().abs().max().item<double>(), 0.0);
}

}  // namespace
}  // namespace saloam
