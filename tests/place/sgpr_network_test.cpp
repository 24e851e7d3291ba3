// SGPR inference against the original PyTorch model's outputs
// (../shared/models/sgpr/reference.json and reference_activations.json).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <limits>
#include <set>

#include <nlohmann/json.hpp>

#include "saloam/core/error.hpp"
#include "saloam/place/graph_json.hpp"
#include "saloam/place/sgpr_network.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

nlohmann::json load_json(const std::string& relative) {
  std::ifstream in(testing::shared_file(relative));
  return nlohmann::json::parse(in);
}

SemanticGraph shared_graph(const std::string& id) {
  return read_graph_json(testing::shared_file("models/sgpr/graph_" + id + ".json"));
}

const SgprNetwork& kitti_network() {
  static const SgprNetwork network = SgprNetwork::load(testing::shared_file("models/sgpr/sgpr_kitti.sgw"));
  return network;
}

TEST(SgprNetwork, ReproducesEveryReferenceScoreOfEveryModel) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto reference = load_json("models/sgpr/reference.json");
  std::map<std::string, SemanticGraph> graphs;
  for (const auto& [id, count] : reference["graph_node_counts"].items()) {
    graphs[id] = shared_graph(id);
    EXPECT_EQ(graphs[id].size(), count.get<std::size_t>()) << id;
  }
  int checked = 0;
  double max_score_error = 0, max_logit_error = 0;
  for (const auto& [name, model] : reference["models"].items()) {
    const SgprNetwork network = SgprNetwork::load(testing::shared_file("models/sgpr/" + model["file"].get<std::string>()));
    std::map<std::string, SgprEmbedding> embeddings;
    for (const auto& [id, graph] : graphs) embeddings[id] = network.embed(graph);
    for (const auto& [pair, expected] : model["scores"].items()) {
      const auto dash = pair.find('-');
      const auto& first = embeddings.at(pair.substr(0, dash));
      const auto& second = embeddings.at(pair.substr(dash + 1));
      EXPECT_NEAR(network.score(first, second), expected.get<double>(), 1e-5) << name << " " << pair;
      max_score_error = std::max(max_score_error, std::abs(network.score(first, second) - expected.get<double>()));
      max_logit_error = std::max(max_logit_error, std::abs(network.logit(first, second) -
                                                           model["logits_before_sigmoid"][pair].get<double>()));
      EXPECT_NEAR(network.logit(first, second), model["logits_before_sigmoid"][pair].get<double>(), 1e-3)
          << name << " " << pair;
      // The batch path must agree with the single-pair path.
      const std::vector<SgprEmbedding> one{second};
      EXPECT_NEAR(network.score_batch(first, one)[0], network.score(first, second), 1e-12);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 9 + 18 * 2);
  std::printf("  %d pairs of 19 models: max score error %.2e, max logit error %.2e\n", checked, max_score_error,
              max_logit_error);
}

// Largest |a - b| over a [node][channel] JSON matrix and our channels x nodes matrix,
// relative to the layer's largest reference magnitude.
double relative_error(const nlohmann::json& reference, const Eigen::MatrixXf& ours) {
  double max_ref = 0, max_diff = 0;
  EXPECT_EQ(reference.size(), static_cast<std::size_t>(ours.cols()));
  for (std::size_t n = 0; n < reference.size(); ++n) {
    EXPECT_EQ(reference[n].size(), static_cast<std::size_t>(ours.rows()));
    for (std::size_t c = 0; c < reference[n].size(); ++c) {
      const double r = reference[n][c].get<double>();
      max_ref = std::max(max_ref, std::abs(r));
      max_diff = std::max(max_diff, std::abs(r - ours(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(n))));
    }
  }
  return max_diff / std::max(max_ref, 1e-30);
}

double relative_error(const nlohmann::json& reference, const Eigen::VectorXf& ours) {
  const Eigen::MatrixXf m = ours;  // channels x 1: one "node" holding all values
  return relative_error(nlohmann::json::array({reference}), m);
}

TEST(SgprNetwork, ReproducesReferenceActivationsLayerByLayer) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto ref = load_json("models/sgpr/reference_activations.json");
  SgprActivations act;
  const SgprEmbedding pooled = kitti_network().embed(shared_graph("0"), &act);

  // Input: [row][node], padding columns all zero.
  for (int r = 0; r < 15; ++r)
    for (int n = 0; n < kSgprNodes; ++n)
      ASSERT_NEAR(act.input(r, n), ref["input_15x100"][r][n].get<double>(), 1e-6) << r << " " << n;

  // kNN of xyz layer 1, compared as multisets of feature vectors (padding indices interchangeable).
  auto feature = [&](int node) {
    return std::array<float, 3>{act.input(0, node), act.input(1, node), act.input(2, node)};
  };
  for (int n = 0; n < kSgprNodes; ++n) {
    std::multiset<std::array<float, 3>> ours, theirs;
    for (int m = 0; m < kSgprNeighbours; ++m) {
      ours.insert(feature(act.knn_xyz1[n][m]));
      theirs.insert(feature(ref["knn_xyz_layer1_100x10"][n][m].get<int>()));
    }
    EXPECT_EQ(ours, theirs) << "node " << n;
  }

  constexpr double kTolerance = 1e-4;
  const std::vector<std::pair<std::string, double>> errors{
      {"xyz1", relative_error(ref["xyz1_100x64"], act.xyz1)},
      {"xyz2", relative_error(ref["xyz2_100x64"], act.xyz2)},
      {"xyz3", relative_error(ref["xyz3_100x32"], act.xyz3)},
      {"sem1", relative_error(ref["sem1_100x64"], act.sem1)},
      {"sem2", relative_error(ref["sem2_100x64"], act.sem2)},
      {"sem3", relative_error(ref["sem3_100x32"], act.sem3)},
      {"embedding", relative_error(ref["embedding_100x32"], act.embedding)},
      {"attention_context", relative_error(ref["attention_context_tanh_32"], act.attention_context)},
      {"attention_weights", relative_error(ref["attention_weights_100"], act.attention_weights)},
      {"pooled", relative_error(ref["pooled_32"], Eigen::VectorXf(pooled))}};
  for (const auto& [layer, error] : errors) {
    EXPECT_LT(error, kTolerance) << layer;
    std::printf("  %-18s max error %.2e of the layer's largest magnitude\n", layer.c_str(), error);
  }
  // Every padding node gets the same attention weight (0.5163 in FORMAT.md).
  for (int n = 38; n < kSgprNodes; ++n) EXPECT_NEAR(act.attention_weights[n], 0.5163, 1e-4);

  SgprPairActivations pair;
  const double score = kitti_network().score(pooled, kitti_network().embed(shared_graph("3")), &pair);
  const auto& ref_pair = ref["pair_0_3"];
  for (int k = 0; k < kSgprTensorNeurons; ++k) {
    EXPECT_NEAR(pair.tensor_network_out[k], ref_pair["tensor_network_out_16"][k].get<double>(), 1e-4 * 48) << k;
    EXPECT_NEAR(pair.fully_connected_out[k], ref_pair["fully_connected_first_out_16"][k].get<double>(), 1e-4 * 25)
        << k;
  }
  EXPECT_NEAR(pair.logit, ref_pair["logit"].get<double>(), 1e-3);
  EXPECT_NEAR(score, ref_pair["score"].get<double>(), 1e-5);
}

TEST(SgprNetwork, PaddingMattersAndOrderMatters) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto& net = kitti_network();
  const auto h0 = net.embed(shared_graph("0"));
  const auto h3 = net.embed(shared_graph("3"));
  EXPECT_NEAR(net.score(h0, h3), 0.997977436, 1e-5);
  EXPECT_NEAR(net.score(h3, h0), 0.98184526, 1e-5);
  EXPECT_GT(std::abs(net.score(h0, h3) - net.score(h3, h0)), 0.01);
}

TEST(SgprNetwork, PermutingNodesLeavesTheEmbeddingUnchanged) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto& net = kitti_network();
  SemanticGraph g = shared_graph("3");
  const auto h = net.embed(g);
  std::reverse(g.nodes.begin(), g.nodes.end());
  std::reverse(g.centers.begin(), g.centers.end());
  EXPECT_LT((net.embed(g) - h).cwiseAbs().maxCoeff(), 1e-4 * h.cwiseAbs().maxCoeff());
}

TEST(SgprNetwork, BatchScoringMatchesPairScoring) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto& net = kitti_network();
  std::vector<SgprEmbedding> stored;
  for (const char* id : {"0", "3", "250"}) stored.push_back(net.embed(shared_graph(id)));
  // More candidates than one internal chunk (64).
  std::vector<SgprEmbedding> many;
  for (int i = 0; i < 150; ++i) many.push_back(stored[static_cast<std::size_t>(i % 3)] * (0.9F + 0.001F * static_cast<float>(i)));
  const auto scores = net.score_batch(stored[0], many);
  ASSERT_EQ(scores.size(), many.size());
  for (std::size_t i = 0; i < many.size(); ++i) EXPECT_NEAR(scores[i], net.score(stored[0], many[i]), 1e-12) << i;
  EXPECT_TRUE(net.score_batch(stored[0], {}).empty());
}

TEST(SgprNetwork, RejectsBadNodeClasses) {
  SALOAM_REQUIRE_SHARED_DATA();
  SemanticGraph g = shared_graph("0");
  g.nodes[0] = 12;
  EXPECT_THROW((void)kitti_network().embed(g), std::invalid_argument);
}

TEST(SgprNetwork, GraphsWithMoreThan100NodesUseTheFirst100) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto& net = kitti_network();
  SemanticGraph g;
  for (int i = 0; i < 120; ++i) {
    g.nodes.push_back(i % kNumNodeClasses);
    g.centers.emplace_back(0.5 * i, std::sin(i), 0.1 * (i % 7));
  }
  SemanticGraph first = g;
  first.nodes.resize(100);
  first.centers.resize(100);
  EXPECT_EQ(net.embed(g), net.embed(first));
}

}  // namespace
}  // namespace saloam

namespace saloam {
namespace {

// Weights within the reader's bounds can still overflow float32 on their way
// through the layers: the network names the model instead of returning NaN.
TEST(SgprNetwork, AnOverflowingModelIsAnErrorNamingItNeverANaN) {
  SgprWeights weights = read_sgpr_weights(testing::source_dir() / "models/sgpr/saloam.sgw");
  for (auto& [name, tensor] : weights.tensors) {
    for (float& v : tensor.values) v = 0.9F * kMaxSgprWeight;
  }
  weights.source = "huge.sgw";
  const SgprNetwork network(weights);
  SemanticGraph graph;
  for (int i = 0; i < 30; ++i) {
    graph.nodes.push_back(i % kNumNodeClasses);
    graph.centers.emplace_back(2.0 * i, 40.0 - i, 0.5);
  }
  const std::string error = testing::input_error_of([&] { (void)network.embed(graph); });
  EXPECT_NE(error.find("huge.sgw: the SGPR network overflows"), std::string::npos) << error;

  // Centres the readers refuse are refused here too, before any arithmetic.
  const SgprNetwork shipped = SgprNetwork::load(testing::source_dir() / "models/sgpr/saloam.sgw");
  graph.centers[3].y() = 1e308;
  EXPECT_THROW((void)shipped.embed(graph), std::invalid_argument);
  graph.centers[3].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)shipped.embed(graph), std::invalid_argument);
}

}  // namespace
}  // namespace saloam
