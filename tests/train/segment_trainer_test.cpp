// The segmentation trainer: a tiny run lowers the loss, is deterministic for
// a seed, and a resumed run equals an uninterrupted one; its model
// description is what --segmenter reads.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/segmentation/segmenter_spec.hpp"
#include "saloam/train/segment_trainer.hpp"
#include "saloam/train/training_run.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

/// Two 16-beam scans of the built-in urban loop with ground-truth labels.
const TrainingScanSet& street() {
  static const TrainingScanSet sequence = [] {
    SourceSpec spec;
    spec.preset = "urban-loop";
    spec.frames = "10:50";
    spec.frame_step = 20;
    spec.beams = 16;
    spec.noisy_labels = false;
    return build_training_scans(spec, FeatureConfig{}, std::nullopt, false);
  }();
  return sequence;
}

SegmentTrainOptions tiny_options(const fs::path& out) {
  SegmentTrainOptions options;
  options.out = out;
  options.epochs = 2;
  options.samples_per_epoch = 4;
  options.batch = 2;
  options.columns = 512;
  options.pixels_per_sample = 16 * 256;
  options.shape.widths = {4, 8, 8};
  options.shape.stem_stride = 2;
  options.shape.context_blocks = 1;
  options.validation_scans = 1;
  options.show_progress = false;
  return options;
}

std::vector<TrainingSample> batch(const ProjectionSpec& projection) {
  std::vector<TrainingSample> samples;
  for (std::uint64_t seed = 0; seed < 2; ++seed)
    samples.push_back(make_training_sample(street().scans.at(seed), projection, ScanAugmentOptions{}, seed, 0));
  return samples;
}

SegNetShape shape_of(const SegmentTrainOptions& options) {
  SegNetShape shape = options.shape;
  shape.in_channels = 6;
  shape.classes = kNumLearningClasses;
  return shape;
}

TEST(SegmentTrainer, TinyRunLowersTheLossDeterministically) {
  set_training_threads(1);
  ASSERT_EQ(street().scans.size(), 2U);
  const SegmentTrainOptions options = tiny_options("unused");
  ProjectionSpec projection;
  projection.columns = 512;
  projection.means = {10, 0, 0, -1, 0.3f, 0.5f};
  projection.stds = {10, 10, 10, 1, 0.2f, 0.5f};
  const auto samples = batch(projection);
  auto losses = [&] {
    SegmentTrainer trainer(shape_of(options), 5, options);
    trainer.set_class_weights(class_weights_from_counts(class_counts({street()})));
    std::vector<double> out;
    for (int i = 0; i < 30; ++i) out.push_back(trainer.step(samples, 1e-2));
    return out;
  };
  const auto first = losses();
  EXPECT_LT(first.back(), 0.75 * first.front());  // measured: 3.18 -> 2.06
  EXPECT_EQ(losses(), first) << "same seed, same samples, one thread: the same losses";
}

TEST(SegmentTrainer, ClassWeightsFavourRareClasses) {
  std::array<std::uint64_t, kNumLearningClasses> counts{};
  counts[0] = 1000;  // unlabeled: ignored
  counts[9] = 900;   // road
  counts[18] = 100;  // pole
  const auto w = class_weights_from_counts(counts);
  EXPECT_EQ(w[0], 0.0);
  EXPECT_EQ(w[1], 0.0);
  EXPECT_NEAR(w[18] / w[9], 3.0, 1e-9);  // 1 / sqrt(frequency)
  EXPECT_NEAR(w[9] + w[18], 2.0, 1e-9);  // mean 1 over the classes present
}

TEST(SegmentTrainer, ClassWeightFactorsScaleTheirClassAndKeepTheMean) {
  std::array<std::uint64_t, kNumLearningClasses> counts{};
  counts[9] = 900;   // road
  counts[18] = 100;  // pole
  counts[16] = 100;  // trunk
  auto factors = uniform_class_factors();
  set_class_weight_factor(factors, "pole", 2.0);
  EXPECT_THROW(set_class_weight_factor(factors, "pol", 2.0), ConfigError);
  EXPECT_THROW(set_class_weight_factor(factors, "trunk", 0.0), ConfigError);
  EXPECT_THROW(set_class_weight_factor(factors, "trunk", 101.0), ConfigError);
  EXPECT_EQ(factors[*learning_class_id("trunk")], 1.0);
  const auto plain = class_weights_from_counts(counts);
  const auto w = class_weights_from_counts(counts, factors);
  EXPECT_NEAR(w[18] / w[16], 2.0, 1e-9);
  EXPECT_NEAR(w[16] / w[9], plain[16] / plain[9], 1e-9);
  EXPECT_NEAR(w[9] + w[16] + w[18], 3.0, 1e-9);
  EXPECT_EQ(learning_class_id("pole"), std::optional<std::uint8_t>(18));
  EXPECT_FALSE(learning_class_id("unlabeled").has_value());
  EXPECT_FALSE(learning_class_id("moving-car").has_value());
}

std::string text_of(const fs::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(SegmentTrainer, AResumedRunEqualsAnUninterruptedOne) {
  testing::TempDir dir;
  const std::vector<TrainingScanSet> data{street()};
  const auto whole = train_segmenter(data, data, tiny_options(dir / "whole"));
  ASSERT_EQ(whole.history.size(), 2U);

  SegmentTrainOptions first = tiny_options(dir / "parts");
  first.epochs = 1;
  ASSERT_EQ(train_segmenter(data, data, first).history.size(), 1U);
  SegmentTrainOptions rest = resumed_options(dir / "parts", tiny_options(dir / "parts"));
  EXPECT_TRUE(rest.resume);
  const auto resumed = train_segmenter(data, data, rest);
  ASSERT_EQ(resumed.history.size(), 2U);
  for (std::size_t e = 0; e < 2; ++e) {
    EXPECT_EQ(resumed.history[e].loss, whole.history[e].loss);
    EXPECT_EQ(resumed.history[e].val_miou, whole.history[e].val_miou);
  }
  // The description names its weights and the training data's channel statistics.
  const SegmenterSpec spec = read_segmenter_spec(dir / "whole" / "model.yaml");
  EXPECT_EQ(spec.network.weights, (dir / "whole" / "model.pt").string());
  EXPECT_EQ(spec.beams, std::vector<int>{16});
  EXPECT_EQ(spec.projection.columns, 512);
  EXPECT_GT(spec.projection.stds[0], 1.0f);
  for (const char* file : {"best.pt", "best.yaml", "training.json", "curves.png", "checkpoint/state.json"})
    EXPECT_TRUE(fs::exists(dir / "whole" / file)) << file;
  EXPECT_EQ(text_of(dir / "parts" / "model.yaml").size(), text_of(dir / "whole" / "model.yaml").size());
}

TEST(SegmentTrainer, RecipesNameBeamCountsAndSegmentationRefusesNoisyLabels) {
  testing::TempDir dir;
  std::ofstream(dir / "recipe.yaml") << "defaults: {frame_step: 10, beams: 32}\n"
                                        "train: [{simulate: 'preset:urban-loop'}, {simulate: 'preset:urban-loop', beams: 16}]\n"
                                        "validation: [{simulate: 'preset:urban-loop', labels: noisy}]\n";
  SourceSpec defaults;
  defaults.noisy_labels = false;
  const DataRecipe recipe = read_data_recipe(dir / "recipe.yaml", defaults);
  EXPECT_EQ(recipe.train[0].beams, 32);
  EXPECT_EQ(recipe.train[1].beams, 16);
  EXPECT_FALSE(recipe.train[0].noisy_labels);
  EXPECT_EQ(recipe.train[1].name(), "sim-urban-loop-s1-k10-gt-b16");
  EXPECT_NE(testing::input_error_of([&] { (void)build_training_scans(recipe.validation[0], FeatureConfig{}, std::nullopt, false); })
                .find("segmentation trains on ground truth"),
            std::string::npos);
  std::ofstream(dir / "bad.yaml") << "train: [{simulate: 'preset:urban-loop', beams: 20}]\nvalidation: [{simulate: 'preset:urban-loop'}]\n";
  EXPECT_NE(testing::input_error_of([&] { (void)read_data_recipe(dir / "bad.yaml"); }).find("beams must be 64, 32 or 16"),
            std::string::npos);
}

TEST(SegmentTrainer, RecipeWeightsDrawSourcesAndCountTheirClassesAsOftenAsSaid) {
  testing::TempDir dir;
  std::ofstream(dir / "recipe.yaml") << "train: [{simulate: 'preset:urban-loop', weight: 4}, {simulate: 'preset:urban-loop'}]\n"
                                        "validation: [{simulate: 'preset:urban-loop'}]\n";
  const DataRecipe recipe = read_data_recipe(dir / "recipe.yaml");
  EXPECT_EQ(recipe.train[0].weight, 4.0);
  EXPECT_EQ(recipe.train[1].weight, 1.0);
  EXPECT_EQ(recipe.train[0].to_json(), recipe.train[1].to_json()) << "the weight is not the data's identity (cache)";
  EXPECT_EQ(recipe_to_json(recipe)["train"][0]["weight"], 4.0);
  EXPECT_FALSE(recipe_to_json(recipe)["train"][1].contains("weight"));
  for (const char* bad : {"0", "-1", "1001", ".nan"}) {
    std::ofstream(dir / "bad.yaml") << "train: [{simulate: 'preset:urban-loop', weight: " << bad
                                    << "}]\nvalidation: [{simulate: 'preset:urban-loop'}]\n";
    EXPECT_NE(testing::input_error_of([&] { (void)read_data_recipe(dir / "bad.yaml"); }).find("weight must lie in (0, 1000]"),
              std::string::npos)
        << bad;
  }
  TrainingScanSet heavy = street();
  heavy.weight = 3.0;
  const auto once = class_counts({street()});
  const auto mixed = class_counts({street(), heavy});
  for (int c = 0; c < kNumLearningClasses; ++c) EXPECT_EQ(mixed[c], 4 * once[c]) << c;
}

/// The first `count` scans of sequence 00 of the real labelled scans
/// (../shared/data/semantickitti_mini), unpacked into `dir`/00.
fs::path real_sequence(const testing::TempDir& dir, int count) {
  const fs::path archive = testing::shared_file("data/semantickitti_mini/semantickitti_mini.tar.xz");
  std::string members;
  for (int k = 0; k < count; ++k)
    members += fmt::format(" semantickitti_mini/sequences/00/velodyne/{0:06d}.bin semantickitti_mini/sequences/00/labels/{0:06d}.label", k);
  const std::string command = "tar -xJf " + testing::quoted(archive) + " -C " + testing::quoted(dir.path()) + members;
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  return dir / "semantickitti_mini/sequences/00";
}

TEST(SegmentTrainer, AFolderStoredAt0To255TrainsAsIts0To1Twin) {
  SALOAM_REQUIRE_SHARED_DATA();
  testing::TempDir dir;
  const fs::path unit = real_sequence(dir, 1);
  const fs::path bytes = dir / "bytes";
  fs::copy(unit, bytes, fs::copy_options::recursive);
  LabelledCloud cloud = read_scan(unit / "velodyne/000000.bin");
  for (auto& r : cloud.remission) r = std::round(r * 255.0f);
  write_scan_bin(bytes / "velodyne/000000.bin", cloud);
  SourceSpec spec;
  spec.kind = SourceSpec::Kind::kFolder;
  spec.frame_step = 1;
  spec.path = unit;
  const TrainingScanSet a = build_training_scans(spec, FeatureConfig{}, std::nullopt, false);
  spec.path = bytes;
  const TrainingScanSet b = build_training_scans(spec, FeatureConfig{}, std::nullopt, false);
  ASSERT_EQ(a.scans.at(0).size(), b.scans.at(0).size());
  std::size_t differ = 0, bright = 0;
  for (std::size_t i = 0; i < a.scans[0].size(); ++i) {
    differ += std::abs(int(a.scans[0].remission[i]) - int(b.scans[0].remission[i])) > 1;
    bright += b.scans[0].remission[i] == 255;
  }
  EXPECT_EQ(differ, 0U) << "0..255 remission divided by 255, as a run reads it";
  EXPECT_LT(bright, b.scans[0].size() / 100) << "not clipped at 1";
}

TEST(SegmentTrainer, TrainingOnRealAndSimulatedScansLowersTheLoss) {
  SALOAM_REQUIRE_SHARED_DATA();
  testing::TempDir dir;
  SourceSpec real;
  real.kind = SourceSpec::Kind::kFolder;
  real.path = real_sequence(dir, 2);
  real.frame_step = 1;
  real.weight = 2.0;
  TrainingScanSet real_scans = build_training_scans(real, FeatureConfig{}, std::nullopt, false);
  ASSERT_EQ(real_scans.scans.size(), 2U);
  EXPECT_EQ(real_scans.scans[0].beams, 64);
  EXPECT_GT(real_scans.scans[0].size(), 100000U);
  EXPECT_EQ(real_scans.weight, 2.0);
  std::size_t road = 0;
  for (const auto t : real_scans.scans[0].target) road += t == 9;
  EXPECT_GT(road, 10000U) << "SemanticKITTI's labels read as learning classes";

  // Alternate steps on the two real scans and on two simulated ones, each
  // batch fixed (its augmentation drawn once): the loss of both must fall.
  set_training_threads(1);
  const SegmentTrainOptions options = tiny_options("unused");
  ProjectionSpec projection;
  projection.columns = 512;
  projection.means = {10, 0, 0, -1, 0.3f, 0.5f};
  projection.stds = {10, 10, 10, 1, 0.2f, 0.5f};
  std::vector<TrainingSample> real_batch;
  for (std::uint64_t k = 0; k < 2; ++k)
    real_batch.push_back(make_training_sample(real_scans.scans[k], projection, ScanAugmentOptions{}, k, 0));
  SegmentTrainer trainer(shape_of(options), 5, options);
  trainer.set_class_weights(class_weights_from_counts(class_counts({real_scans, street()})));
  std::vector<double> real_loss, sim_loss;
  for (int i = 0; i < 30; ++i) {
    real_loss.push_back(trainer.step(real_batch, 1e-2));
    sim_loss.push_back(trainer.step(batch(projection), 1e-2));
  }
  std::printf("real %.3f -> %.3f, simulated %.3f -> %.3f\n", real_loss.front(), real_loss.back(), sim_loss.front(),
              sim_loss.back());
  EXPECT_LT(real_loss.back(), 0.75 * real_loss.front());
  EXPECT_LT(sim_loss.back(), 0.75 * sim_loss.front());
}

}  // namespace
}  // namespace saloam

namespace saloam {
namespace {

/// A scan of `beams` rings around the sensor (a cylinder 10 m away, one point
/// per degree), every point of class `target`.
TrainingScan ring_cylinder(int beams, std::uint8_t target) {
  TrainingScan scan;
  scan.beams = beams;
  for (int ring = 0; ring < beams; ++ring)
    for (int degree = 0; degree < 360; ++degree) {
      const double azimuth = degree * M_PI / 180.0;
      const double z = 1.0 - 0.2 * ring;  // top ring first
      scan.xyz.push_back({static_cast<std::int16_t>(std::lround(10.0 * std::cos(azimuth) / kScanPositionStep)),
                          static_cast<std::int16_t>(std::lround(10.0 * std::sin(azimuth) / kScanPositionStep)),
                          static_cast<std::int16_t>(std::lround(z / kScanPositionStep))});
      scan.remission.push_back(100);
      scan.target.push_back(target);
      scan.ring.push_back(static_cast<std::uint8_t>(ring));
    }
  return scan;
}

ScanAugmentOptions no_augmentation() {
  ScanAugmentOptions a;
  a.rotate = false;
  a.flip = a.max_tilt_deg = a.max_height_shift = a.max_range_noise = 0;
  a.max_point_dropout = a.max_ring_dropout = a.occlusion = a.remission_constant = 0;
  a.remission_gamma = 1;
  a.remission_gain = a.remission_offset = a.remission_noise = 0;
  return a;
}

/// The class of each image row (0: none; -1: more than one).
std::vector<int> row_classes(const TrainingSample& sample) {
  std::vector<int> rows(static_cast<std::size_t>(sample.rows), 0);
  for (int y = 0; y < sample.rows; ++y)
    for (int x = 0; x < sample.cols; ++x) {
      const auto c = static_cast<int>(sample.target[static_cast<std::size_t>(y * sample.cols + x)]);
      if (c == 0) continue;
      auto& row = rows[static_cast<std::size_t>(y)];
      row = row == 0 || row == c ? c : -1;
    }
  return rows;
}

TEST(SegmentTrainingSamples, MixingTakesAlternateRingBandsFromTheSecondScan) {
  constexpr std::uint8_t kCar = 1, kRoad = 9;
  const TrainingScan first = ring_cylinder(16, kCar), second = ring_cylinder(16, kRoad);
  ProjectionSpec projection;
  projection.columns = 512;
  ScanAugmentOptions mixing = no_augmentation();
  mixing.mix = 1;
  for (std::uint64_t seed = 0; seed < 6; ++seed) {
    const auto rows = row_classes(make_training_sample(first, projection, mixing, seed, 0, &second));
    // Some band count k in 2..6 explains every row: even bands the first scan's, odd the second's.
    bool explained = false;
    for (int k = 2; k <= 6 && !explained; ++k) {
      explained = true;
      for (int y = 0; y < 16; ++y) explained &= rows[static_cast<std::size_t>(y)] == ((y * k / 16) % 2 ? kRoad : kCar);
    }
    EXPECT_TRUE(explained) << "seed " << seed;
  }
  // Never mixed: at mix 0, without a partner, or with a partner of another beam count.
  const std::vector<int> all_car(16, kCar);
  EXPECT_EQ(row_classes(make_training_sample(first, projection, no_augmentation(), 3, 0, &second)), all_car);
  EXPECT_EQ(row_classes(make_training_sample(first, projection, mixing, 3, 0)), all_car);
  const TrainingScan other_beams = ring_cylinder(32, kRoad);
  EXPECT_EQ(row_classes(make_training_sample(first, projection, mixing, 3, 0, &other_beams)), all_car);
}

TEST(SegmentTrainingSamples, MixIsAnAugmentationOfTheCommandLine) {
  ScanAugmentOptions a;
  EXPECT_EQ(a.mix, 0.0);  // the shipped recipes draw no second scan
  set_augment_option(a, "mix", "0.5");
  EXPECT_EQ(a.mix, 0.5);
  EXPECT_THROW(set_augment_option(a, "mix", "1.5"), ConfigError);
}

}  // namespace
}  // namespace saloam
