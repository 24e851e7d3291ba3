// The segmentation network's two doors: saloam's own SegNet weights and a
// TorchScript model with its description, both run by the plugin that
// saloam loads with dlopen; the plugin's labels equal the trainer's
// in-process inference, do not depend on the number of workers, and every
// broken model is a clear error naming its file.

#include <torch/script.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "saloam/segmentation/segmented_source.hpp"
#include "saloam/segmentation/segmenter.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/train/segment_trainer.hpp"
#include "saloam/train/training_run.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

const fs::path kPlugin = SALOAM_TEST_SEGMENT_PLUGIN;

/// A few 16-beam scans of the built-in urban loop.
const std::vector<LabelledCloud>& scans() {
  static const std::vector<LabelledCloud> clouds = [] {
    SimulationOptions options;
    options.preset = "urban-loop";
    options.first_frame = 20;
    options.end_frame = 80;
    options.stride = 20;
    options.beams = 16;
    options.show_progress = false;
    const SimulatedSequence sequence(options);
    std::vector<LabelledCloud> out;
    for (std::size_t k = 0; k < sequence.size(); ++k) out.push_back(sequence.render(k).cloud);
    return out;
  }();
  return clouds;
}

/// A small SegNet, trained a few steps on one scan so that its batch norm
/// statistics are not the initial ones, saved as `dir/model.pt` with its description.
struct SavedSegNet {
  SegmenterSpec spec;
  std::unique_ptr<SegmentTrainer> trainer;
};

SavedSegNet small_segnet(const fs::path& dir) {
  set_training_threads(1);
  SavedSegNet out;
  SegmentTrainOptions options;
  out.spec.projection.columns = 512;
  out.spec.beams = {16};
  out.spec.classes = semantickitti_learning_classes();
  out.spec.network.shape.widths = {4, 8, 8};
  out.spec.network.shape.stem_stride = 2;
  out.spec.network.shape.context_blocks = 1;
  out.spec.network.shape.in_channels = 6;
  out.spec.network.shape.classes = 20;
  out.spec.projection.means = {10, 0, 0, -1, 0.3f, 0.5f};
  out.spec.projection.stds = {10, 10, 10, 1, 0.2f, 0.5f};
  out.trainer = std::make_unique<SegmentTrainer>(out.spec.network.shape, 3, options);
  const auto rings = point_rings(scans().front(), FeatureConfig{});
  const TrainingScan scan = compact_scan(scans().front(), rings.ring, rings.beams);
  std::vector<TrainingSample> batch;
  for (std::uint64_t seed = 0; seed < 2; ++seed)
    batch.push_back(make_training_sample(scan, out.spec.projection, ScanAugmentOptions{}, seed, 0));
  for (int i = 0; i < 3; ++i) out.trainer->step(batch, 1e-2);
  out.trainer->save_model(dir / "model.pt");
  out.spec.network.weights = (dir / "model.pt").string();
  out.spec.file = dir / "model.yaml";
  std::ofstream(dir / "model.yaml") << segmenter_spec_yaml(out.spec, dir);
  return out;
}

TEST(SegmenterPlugin, SegNetWeightsRunAsTheTrainerRunsThem) {
  testing::TempDir dir;
  SavedSegNet saved = small_segnet(dir.path());
  const Segmenter plugin(read_segmenter_spec(dir / "model.yaml"), kPlugin);
  const Segmenter in_process(saved.spec, saved.trainer->runner());
  std::size_t same = 0, total = 0;
  for (const auto& cloud : scans()) {
    const auto a = plugin.labels(cloud), b = in_process.labels(cloud);
    ASSERT_EQ(a.size(), cloud.size());
    for (std::size_t i = 0; i < a.size(); ++i) same += a[i] == b[i];
    total += a.size();
    for (const auto label : a) EXPECT_NE(to_learning_class(label), 0) << "class 0 is never predicted";
  }
  // The plugin folds batch norm into the convolutions: the same function up
  // to rounding, which may flip a near tie.
  EXPECT_GE(static_cast<double>(same), 0.999 * static_cast<double>(total));
}

/// Serves scans() as a source.
class ListSource final : public FrameSource {
 public:
  ListSource() {
    info_.name = "list";
    for (std::size_t i = 0; i < scans().size(); ++i) info_.times.push_back(0.1 * static_cast<double>(i));
  }
  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  LabelledCloud scan(std::size_t i) override { return scans().at(i); }

 private:
  SourceInfo info_;
};

std::vector<std::vector<std::uint16_t>> segmented(const fs::path& model, int workers) {
  const SegmenterSpec spec = read_segmenter_spec(model);
  SegmentedSource source(std::make_unique<ListSource>(), [&] { return std::make_unique<Segmenter>(spec, kPlugin); },
                         workers, 2);
  EXPECT_TRUE(source.info().has_labels);
  EXPECT_FALSE(source.info().rereadable);
  std::vector<std::vector<std::uint16_t>> labels;
  for (std::size_t i = 0; i < source.size(); ++i) {
    const LabelledCloud cloud = source.scan(i);
    EXPECT_TRUE(cloud.has_labels);
    labels.push_back(cloud.label);
  }
  EXPECT_EQ(source.stage_times().back().name, "segmentation");
  EXPECT_EQ(source.stage_times().back().per_frame.size(), source.size());
  return labels;
}

TEST(SegmenterPlugin, LabelsAreDeterministicAndDoNotDependOnTheWorkers) {
  testing::TempDir dir;
  small_segnet(dir.path());
  const auto one = segmented(dir / "model.yaml", 1);
  EXPECT_EQ(segmented(dir / "model.yaml", 1), one);
  EXPECT_EQ(segmented(dir / "model.yaml", 3), one);
}

/// A TorchScript network written by the test: class "car" for pixels nearer
/// than 10 m, "road" beyond (the first channel is the range, unnormalised).
void write_torchscript_rule(const fs::path& file, int classes) {
  torch::jit::Module module("RangeRule");
  module.define(R"(
def forward(self, x):
    near = (x[:, 0:1] < 10.0).float()
    zeros = torch.zeros_like(near)
    parts = [zeros, near]
    for i in range(7):
        parts.append(zeros)
    parts.append(1.0 - near)
    for i in range()" + std::to_string(classes - 10) + R"():
        parts.append(zeros)
    return torch.cat(parts, 1)
)");
  module.save(file.string());
}

void write_rangenet_description(const fs::path& file, const std::string& weights) {
  std::ofstream(file) << "format: saloam-segmenter 1\n"
                         "network: {type: torchscript, file: " << weights << "}\n"
                         "projection: {rows: 64, fov_up_deg: 3.0, fov_down_deg: -25.0, columns: 1024,\n"
                         "  channels: [range, x, y, z, remission], means: [0, 0, 0, 0, 0], stds: [1, 1, 1, 1, 1]}\n"
                         "classes: semantickitti\n"
                         "knn: {k: 5, window: 5, cutoff: 1.0, sigma: 1.0}\n";
}

TEST(SegmenterPlugin, RunsATorchScriptNetworkWithItsDescription) {
  testing::TempDir dir;
  write_torchscript_rule(dir / "rule.pt", 20);
  write_rangenet_description(dir / "rule.yaml", "rule.pt");
  const Segmenter segmenter(read_segmenter_spec(dir / "rule.yaml"), kPlugin);
  const LabelledCloud& cloud = scans().front();
  const auto labels = segmenter.labels(cloud);
  std::size_t agree = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    agree += labels[i] == (cloud.points[i].norm() < 10.0f ? cls::kCar : cls::kRoad);
  // The vote may move points within a metre of the 10 m boundary.
  EXPECT_GE(static_cast<double>(agree), 0.98 * static_cast<double>(cloud.size()));
}

TEST(SegmenterPlugin, TheDynamicBiasTipsOnlyCloseCallsToDynamicClasses) {
  testing::TempDir dir;
  write_torchscript_rule(dir / "rule.pt", 20);  // logits 1 for car or road, 0 for every other class
  const LabelledCloud& cloud = scans().front();
  auto share_of_persons = [&](const std::string& decision) {
    write_rangenet_description(dir / "rule.yaml", "rule.pt");
    std::ofstream(dir / "rule.yaml", std::ios::app) << decision;
    const auto labels = Segmenter(read_segmenter_spec(dir / "rule.yaml"), kPlugin).labels(cloud);
    return static_cast<double>(std::count(labels.begin(), labels.end(), cls::kPerson)) / static_cast<double>(labels.size());
  };
  EXPECT_EQ(share_of_persons("decision: {dynamic_bias: 0.5}\n"), 0.0) << "a margin of 1 is not a close call at 0.5";
  EXPECT_EQ(share_of_persons("decision: {dynamic_bias: 2}\n"), 1.0) << "person is the first dynamic class";
}

TEST(SegmenterPlugin, TheConfidenceIsTheNetworksProbabilityOfThePointsClass) {
  testing::TempDir dir;
  write_torchscript_rule(dir / "rule.pt", 20);  // logits 1 for car or road, 0 for the 18 other classes
  const LabelledCloud& cloud = scans().front();
  // The softmax at a pixel: the rule's class e / (e + 19) = 0.125, another 1 / (e + 19) = 0.046 (a point
  // the vote moved across the 10 m boundary, whose pixel shows the other class).
  const double sure = std::exp(1.0) / (std::exp(1.0) + 19.0), other = 1.0 / (std::exp(1.0) + 19.0);
  auto segment = [&](const std::string& decision) {
    write_rangenet_description(dir / "rule.yaml", "rule.pt");
    std::ofstream(dir / "rule.yaml", std::ios::app) << decision;
    return Segmenter(read_segmenter_spec(dir / "rule.yaml"), kPlugin).segment(cloud, true);
  };
  const Segmentation all = segment("");
  ASSERT_EQ(all.confidence.size(), cloud.size());
  std::size_t as_sure = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    as_sure += std::abs(all.confidence[i] - sure) < 1e-6;
    EXPECT_TRUE(std::abs(all.confidence[i] - sure) < 1e-6 || std::abs(all.confidence[i] - other) < 1e-6)
        << "point " << i << ": " << all.confidence[i];
  }
  EXPECT_GE(static_cast<double>(as_sure), 0.98 * static_cast<double>(cloud.size()));
  EXPECT_EQ(all.labels, Segmenter(read_segmenter_spec(dir / "rule.yaml"), kPlugin).labels(cloud))
      << "asking for the confidence changes no label";

  const Segmentation below = segment("decision: {min_confidence: 0.12}\n");
  EXPECT_EQ(static_cast<std::size_t>(std::count(below.labels.begin(), below.labels.end(), cls::kUnlabeled)),
            cloud.size() - as_sure)
      << "the points the vote moved are left unlabeled, the others keep their class";
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (below.labels[i] != cls::kUnlabeled) {
      EXPECT_EQ(below.labels[i], all.labels[i]) << "point " << i;
    }
  }
  const Segmentation above = segment("decision: {min_confidence: 0.13}\n");
  EXPECT_EQ(static_cast<std::size_t>(std::count(above.labels.begin(), above.labels.end(), cls::kUnlabeled)), cloud.size())
      << "no point is sure enough";
}

TEST(SegmenterPlugin, BrokenModelsAreErrorsNamingTheFile) {
  testing::TempDir dir;
  small_segnet(dir.path());
  const SegmenterSpec good = read_segmenter_spec(dir / "model.yaml");
  auto error_of = [](const SegmenterSpec& spec) {
    return testing::input_error_of([&] { (void)Segmenter(spec, kPlugin).labels(scans().front()); });
  };
  SegmenterSpec missing = good;
  missing.network.weights = (dir / "nothing.pt").string();
  EXPECT_NE(error_of(missing).find("nothing.pt: network (named by"), std::string::npos) << error_of(missing);

  std::ofstream(dir / "garbage.pt") << "not a network";
  SegmenterSpec garbage = good;
  garbage.network.weights = (dir / "garbage.pt").string();
  EXPECT_NE(error_of(garbage).find("garbage.pt: not a usable SegNet weights file"), std::string::npos) << error_of(garbage);

  SegmenterSpec wider = good;
  wider.network.shape.widths = {8, 8, 8};
  EXPECT_NE(error_of(wider).find("model.pt: not a usable SegNet weights file"), std::string::npos) << error_of(wider);

  SegmenterSpec other_beams = good;
  other_beams.beams = {64};
  EXPECT_NE(error_of(other_beams).find("the model is made for 64-beam scans; this scan has 16 rings"), std::string::npos)
      << error_of(other_beams);

  write_torchscript_rule(dir / "rule17.pt", 17);
  write_rangenet_description(dir / "rule17.yaml", "rule17.pt");
  const std::string classes = error_of(read_segmenter_spec(dir / "rule17.yaml"));
  EXPECT_NE(classes.find("rule17.pt: the network rejects"), std::string::npos) << classes;
  EXPECT_NE(classes.find("not [1, 20, 64, 1024]"), std::string::npos) << classes;

  const std::string plugin = testing::input_error_of([&] { Segmenter(good, dir / "no_plugin.so"); });
  EXPECT_NE(plugin.find("no_plugin.so: not found: segmentation needs the network plugin"), std::string::npos) << plugin;
}

}  // namespace
}  // namespace saloam
