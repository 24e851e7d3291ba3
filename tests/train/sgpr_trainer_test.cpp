// The trainer: a tiny run lowers the loss and ranks positives above
// negatives, its weights round-trip through .sgw into the Eigen inference,
// runs are deterministic for a seed, and a resumed run equals an
// uninterrupted one.

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "saloam/place/sgpr_network.hpp"
#include "saloam/train/sgpr_trainer.hpp"
#include "saloam/train/training_run.hpp"
#include "synthetic_graphs.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

std::vector<char> file_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Pairs of the street: positives from the drive back (reverse revisits), negatives far apart.
struct PairSet {
  std::vector<const SemanticGraph*> first, second;
  std::vector<float> targets;
};

PairSet street_pairs(const GraphSequence& s) {
  PairSet set;
  const std::size_t forward = s.graphs.size() / 2;
  for (std::size_t i = 0; i + 1 < forward; i += 8) {
    // The frame of the way back nearest to frame i (1 m away, facing the other way).
    std::size_t back = forward;
    for (std::size_t j = forward; j < s.graphs.size(); ++j)
      if ((s.positions[j] - s.positions[i]).norm() < (s.positions[back] - s.positions[i]).norm()) back = j;
    set.first.push_back(&s.graphs[i]);
    set.second.push_back(&s.graphs[back]);
    set.targets.push_back(1.0F);
    const std::size_t far = (i + forward / 2) % forward;
    set.first.push_back(&s.graphs[i]);
    set.second.push_back(&s.graphs[far]);
    set.targets.push_back(0.0F);
  }
  return set;
}

TEST(SgprTrainer, TinyRunLowersTheLossAndRoundTripsToTheEigenInference) {
  set_training_threads(1);
  const GraphSequence street = testing::synthetic_street(1);
  const PairSet pairs = street_pairs(street);
  ASSERT_GE(pairs.targets.size(), 20U);
  SgprTrainer trainer(7, SgprOptimizerOptions{});
  const double first_loss = trainer.step(pairs.first, pairs.second, pairs.targets);
  double loss = first_loss;
  for (int i = 0; i < 25; ++i) loss = trainer.step(pairs.first, pairs.second, pairs.targets);
  EXPECT_LT(loss, 0.5 * first_loss);

  // Eval mode: positives above negatives on average, and the lowest positive
  // above most negatives.
  const auto logits = trainer.logits(pairs.first, pairs.second);
  double positive = 0, negative = 0;
  for (std::size_t k = 0; k < logits.size(); ++k) (pairs.targets[k] > 0.5F ? positive : negative) += logits[k];
  EXPECT_GT(positive, negative);

  // Written as .sgw and run by the Eigen inference: the same logits.
  testing::TempDir dir;
  write_sgpr_weights(dir / "tiny.sgw", trainer.weights());
  const SgprNetwork eigen = SgprNetwork::load(dir / "tiny.sgw");
  for (std::size_t k = 0; k < logits.size(); ++k)
    EXPECT_NEAR(eigen.logit(eigen.embed(*pairs.first[k]), eigen.embed(*pairs.second[k])), logits[k], 1e-3) << k;
}

SgprTrainOptions tiny_options(const std::filesystem::path& out, int epochs) {
  SgprTrainOptions o;
  o.out = out;
  o.epochs = epochs;
  o.batch = 8;
  o.seed = 5;
  o.pairs_per_epoch = 32;
  o.show_progress = false;
  return o;
}

TEST(SgprTrainer, SameSeedGivesIdenticalWeightsAndTheRunWritesItsFiles) {
  const std::vector<GraphSequence> train{testing::synthetic_street(2, 120.0)};
  const std::vector<GraphSequence> validation{testing::synthetic_street(3, 80.0)};
  testing::TempDir a, b;
  const auto result = train_sgpr(train, validation, tiny_options(a.path(), 1));
  (void)train_sgpr(train, validation, tiny_options(b.path(), 1));
  ASSERT_EQ(result.history.size(), 1U);
  EXPECT_EQ(result.history[0].pairs, 32U);
  EXPECT_GT(result.history[0].pairs_per_second, 0.0);
  for (const char* f : {"model.sgw", "best.sgw", "training.json", "curves.png", "checkpoint/state.json",
                        "checkpoint/optimizer.pt", "checkpoint/model.sgw"})
    EXPECT_TRUE(std::filesystem::is_regular_file(a / f)) << f;
  EXPECT_EQ(file_bytes(a / "model.sgw"), file_bytes(b / "model.sgw"));
  // A different seed gives different weights.
  testing::TempDir c;
  auto other = tiny_options(c.path(), 1);
  other.seed = 6;
  (void)train_sgpr(train, validation, other);
  EXPECT_NE(file_bytes(a / "model.sgw"), file_bytes(c / "model.sgw"));
}

TEST(SgprTrainer, ResumedRunEqualsAnUninterruptedOne) {
  const std::vector<GraphSequence> train{testing::synthetic_street(2, 120.0)};
  const std::vector<GraphSequence> validation{testing::synthetic_street(3, 80.0)};
  testing::TempDir whole, split;
  (void)train_sgpr(train, validation, tiny_options(whole.path(), 2));
  (void)train_sgpr(train, validation, tiny_options(split.path(), 1));
  auto resume = tiny_options(split.path(), 2);
  resume.resume = true;
  const auto result = train_sgpr(train, validation, resume);
  ASSERT_EQ(result.history.size(), 2U);
  EXPECT_EQ(result.history[1].epoch, 2);
  EXPECT_EQ(file_bytes(whole / "model.sgw"), file_bytes(split / "model.sgw"));
  // Resuming with other options is refused.
  auto changed = resume;
  changed.batch = 4;
  EXPECT_THROW((void)train_sgpr(train, validation, changed), ConfigError);
}

TEST(SgprTrainingData, PairsFollowTheDistanceThresholds) {
  const GraphSequence street = testing::synthetic_street(4, 60.0);
  const auto positives = positive_pairs(std::span(&street, 1), PairRecipe{});
  ASSERT_FALSE(positives.empty());
  for (const auto& p : positives) EXPECT_LE((street.positions[p.first] - street.positions[p.second]).norm(), 3.0);
  for (const auto j : negative_candidates(street, 0, PairRecipe{}))
    EXPECT_GT((street.positions[j] - street.positions[0]).norm(), 20.0);
}

TEST(SgprTrainingData, MinimumGapKeepsOnlyRevisitsAsPositives) {
  // The street is driven out and back: neighbouring frames and the return
  // pass both give positives; a gap of 20 frames keeps revisits only.
  const GraphSequence street = testing::synthetic_street(4, 60.0);
  const auto all = positive_pairs(std::span(&street, 1), PairRecipe{});
  PairRecipe revisits;
  revisits.positive_min_gap = 20;
  const auto far = positive_pairs(std::span(&street, 1), revisits);
  ASSERT_FALSE(far.empty());
  EXPECT_LT(far.size(), all.size());
  std::size_t near_in_all = 0;
  for (const auto& p : all) near_in_all += p.second - p.first < 20;
  EXPECT_GT(near_in_all, 0U);
  for (const auto& p : far) {
    EXPECT_GE(p.second - p.first, 20U);
    EXPECT_LE((street.positions[p.first] - street.positions[p.second]).norm(), 3.0);
  }
  EXPECT_EQ(far.size(), all.size() - near_in_all);
}

TEST(SgprTrainingData, AugmentationIsARigidMotionWithoutNoise) {
  const GraphSequence street = testing::synthetic_street(4, 60.0);
  const SemanticGraph& g = street.graphs[5];
  AugmentOptions rigid;
  rigid.jitter_sigma = 0;
  rigid.scale_min = rigid.scale_max = 1;
  rigid.node_dropout = 0;
  std::mt19937_64 rng(1);
  const SemanticGraph a = augment_graph(g, rigid, rng);
  ASSERT_EQ(a.size(), g.size());
  EXPECT_EQ(a.nodes, g.nodes);
  for (std::size_t i = 1; i < g.size(); ++i)
    EXPECT_NEAR((a.centers[i] - a.centers[0]).norm(), (g.centers[i] - g.centers[0]).norm(), 1e-9);
  AugmentOptions drop_all = rigid;
  drop_all.node_dropout = 1.0;
  EXPECT_EQ(augment_graph(g, drop_all, rng).size(), 1U);  // never an empty graph
}

TEST(SgprTrainingData, RecipeErrorsNameTheFileAndTheEntry) {
  testing::TempDir dir;
  const auto write = [&](const std::string& text) {
    std::ofstream(dir / "recipe.yaml") << text;
    return testing::input_error_of([&] { (void)read_data_recipe(dir / "recipe.yaml"); });
  };
  EXPECT_NE(write("train: []\nvalidation: []\n").find("non-empty `train:`"), std::string::npos);
  std::ofstream(dir / "poses.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n";
  EXPECT_NE(write("train: [{simulate: poses.txt}]\nvalidation: [{simulate: poses.txt}]\n").find("needs `calib:`"),
            std::string::npos);
  EXPECT_NE(write("train: [{simulate: poses.txt, calib: poses.txt, colour: red}]\nvalidation: [{folder: .}]\n")
                .find("train[0]: unknown key 'colour'"),
            std::string::npos);
  // A list where a key belongs, at each level: an InputError naming the file.
  EXPECT_NE(write("train: [{folder: .}]\nvalidation: [{folder: .}]\n[1, 2]: 3\n")
                .find("recipe.yaml: line 3: a key that is not a name"),
            std::string::npos);
  EXPECT_NE(write("defaults: {[1]: 2}\ntrain: [{folder: .}]\nvalidation: [{folder: .}]\n")
                .find("recipe.yaml: line 1: a key in 'defaults' that is not a name"),
            std::string::npos);
  EXPECT_NE(write("train: [{folder: ., [1]: 2}]\nvalidation: [{folder: .}]\n").find("recipe.yaml: line 1: a key in 'train[0]' that is not a name"),
            std::string::npos);
  // A key given twice (yaml-cpp keeps both; which one a lookup finds is not what was meant).
  EXPECT_NE(write("train: [{folder: ., seed: 1, seed: 2}]\nvalidation: [{folder: .}]\n")
                .find("recipe.yaml: 'train[0].seed' is given twice (lines 1 and 1)"),
            std::string::npos);
  // Read as every other YAML file: one document, invalid YAML named, a folder in its place refused.
  EXPECT_NE(write("train: [{folder: .}]\nvalidation: [{folder: .}]\n---\ntrain: [{folder: .}]\n")
                .find("recipe.yaml: holds 2 YAML documents (separated by '---'); a data recipe is one"),
            std::string::npos);
  EXPECT_NE(write("train: [{folder: .\n").find("recipe.yaml: not valid YAML (line"), std::string::npos);
  std::filesystem::create_directory(dir / "folder.yaml");
  EXPECT_NE(testing::input_error_of([&] { (void)read_data_recipe(dir / "folder.yaml"); }).find("folder.yaml"),
            std::string::npos);
  const std::string ok = write("defaults: {calib: poses.txt, frame_step: 3}\ntrain: [{simulate: poses.txt, frames: '0:9'}]\n"
                               "validation: [{folder: ., labels: here}]\n");
  EXPECT_EQ(ok, "no error");
  const DataRecipe recipe = read_data_recipe(dir / "recipe.yaml");
  EXPECT_EQ(recipe.train.at(0).frame_step, 3U);
  EXPECT_EQ(recipe.train.at(0).calib, dir / "poses.txt");
  EXPECT_EQ(recipe.validation.at(0).labels, dir / "here");
}

}  // namespace
}  // namespace saloam
