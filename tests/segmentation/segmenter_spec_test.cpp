#include "saloam/segmentation/segmenter_spec.hpp"

#include <algorithm>
#include <fstream>

#include <gtest/gtest.h>

#include "saloam/core/semantic_classes.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

const char* const kRangeNet = R"(format: saloam-segmenter 1
network: {type: torchscript, file: rangenet.pt}
projection:
  rows: 64
  fov_up_deg: 3.0
  fov_down_deg: -25.0
  columns: 2048
  channels: [range, x, y, z, remission]
  means: [12.12, 10.88, 0.23, -1.04, 0.21]
  stds: [12.32, 11.47, 6.91, 0.86, 0.16]
classes: semantickitti
knn: {k: 5, window: 5, cutoff: 1.0, sigma: 1.0}
)";

const char* const kSegNet = R"(format: saloam-segmenter 1
network: {type: segnet, file: weights/model.pt, widths: [8, 16, 32], stem_stride: 2, context_blocks: 1}
projection:
  rows: ring
  beams: [16, 32, 64]
  columns: 1024
  channels: [range, remission, mask]
  means: [10, 0.3, 0.5]
  stds: [8, 0.2, 0.5]
classes: [unlabeled, car, road, building]
knn: {k: 3, window: 3, cutoff: 0.5, sigma: 2.0}
)";

std::string error_of(const std::string& yaml) {
  return testing::input_error_of([&] { (void)parse_segmenter_spec(yaml, "/models/m.yaml"); });
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(SegmenterSpec, ReadsARangeNetDescription) {
  const SegmenterSpec spec = parse_segmenter_spec(kRangeNet, "/models/rangenet.yaml");
  EXPECT_EQ(spec.network.format, NetworkFormat::kTorchScript);
  EXPECT_EQ(spec.network.weights, "/models/rangenet.pt");
  EXPECT_EQ(spec.projection.row_mode, RowMode::kElevation);
  EXPECT_EQ(spec.projection.rows, 64);
  EXPECT_DOUBLE_EQ(spec.projection.fov_down_deg, -25.0);
  ASSERT_EQ(spec.projection.channels.size(), 5u);
  EXPECT_EQ(spec.projection.channels[4], ImageChannel::kRemission);
  EXPECT_FLOAT_EQ(spec.projection.stds[3], 0.86f);
  ASSERT_EQ(spec.classes.size(), 20u);
  EXPECT_EQ(spec.classes[1], cls::kCar);
  EXPECT_EQ(spec.classes[19], cls::kTrafficSign);
  EXPECT_EQ(spec.network.shape.in_channels, 5);
  EXPECT_EQ(spec.network.shape.classes, 20);
}

TEST(SegmenterSpec, ReadsASegNetDescriptionAndWritesItBack) {
  const SegmenterSpec spec = parse_segmenter_spec(kSegNet, "/models/m.yaml");
  EXPECT_EQ(spec.network.format, NetworkFormat::kSegNet);
  EXPECT_EQ(spec.network.weights, "/models/weights/model.pt");
  EXPECT_EQ(spec.network.shape.widths, (std::array<int, 3>{8, 16, 32}));
  EXPECT_EQ(spec.network.shape.stem_stride, 2);
  EXPECT_EQ(spec.projection.row_mode, RowMode::kRing);
  EXPECT_EQ(spec.beams, (std::vector<int>{16, 32, 64}));
  EXPECT_EQ(spec.classes, (std::vector<std::uint16_t>{cls::kUnlabeled, cls::kCar, cls::kRoad, cls::kBuilding}));
  EXPECT_EQ(spec.knn.k, 3);
  EXPECT_DOUBLE_EQ(spec.knn.sigma, 2.0);

  const SegmenterSpec again = parse_segmenter_spec(segmenter_spec_yaml(spec, "/models"), "/models/m.yaml");
  EXPECT_EQ(again.network.weights, spec.network.weights);
  EXPECT_EQ(again.network.shape.widths, spec.network.shape.widths);
  EXPECT_EQ(again.projection.columns, spec.projection.columns);
  EXPECT_EQ(again.projection.means, spec.projection.means);
  EXPECT_EQ(again.beams, spec.beams);
  EXPECT_EQ(again.classes, spec.classes);
  EXPECT_EQ(again.knn.window, spec.knn.window);
}

TEST(SegmenterSpec, TheDynamicBiasOffsetsTheDynamicClassesOnly) {
  const SegmenterSpec plain = parse_segmenter_spec(kRangeNet, "/models/m.yaml");
  EXPECT_EQ(plain.dynamic_bias, 0.0);
  EXPECT_TRUE(decision_offsets(plain).empty()) << "no bias: the plain argmax";

  const SegmenterSpec biased = parse_segmenter_spec(std::string(kRangeNet) + "decision: {dynamic_bias: 1.5}\n", "/models/m.yaml");
  EXPECT_DOUBLE_EQ(biased.dynamic_bias, 1.5);
  const auto offsets = decision_offsets(biased);
  ASSERT_EQ(offsets.size(), biased.classes.size());
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    const bool dynamic = biased.classes[k] == cls::kPerson || biased.classes[k] == cls::kBicyclist ||
                         biased.classes[k] == cls::kMotorcyclist;
    EXPECT_EQ(offsets[k], dynamic ? 1.5f : 0.0f) << class_name(biased.classes[k]);
  }
  const SegmenterSpec again = parse_segmenter_spec(segmenter_spec_yaml(biased, "/models"), "/models/m.yaml");
  EXPECT_DOUBLE_EQ(again.dynamic_bias, 1.5);

  EXPECT_NE(error_of(std::string(kRangeNet) + "decision: {dynamic_bias: -1}\n").find("decision.dynamic_bias: -1 is outside"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kRangeNet) + "decision: {static_bias: 1}\n").find("decision.static_bias: unknown key"),
            std::string::npos);
}

TEST(SegmenterSpec, TheMinimumConfidenceIsAProbabilityAndWrittenBack) {
  EXPECT_EQ(parse_segmenter_spec(kRangeNet, "/models/m.yaml").min_confidence, 0.0) << "every point labelled";
  const SegmenterSpec sure = parse_segmenter_spec(std::string(kRangeNet) + "decision: {min_confidence: 0.7}\n", "/models/m.yaml");
  EXPECT_DOUBLE_EQ(sure.min_confidence, 0.7);
  EXPECT_TRUE(decision_offsets(sure).empty()) << "it moves no logit";
  EXPECT_DOUBLE_EQ(parse_segmenter_spec(segmenter_spec_yaml(sure, "/models"), "/models/m.yaml").min_confidence, 0.7);
  EXPECT_NE(error_of(std::string(kRangeNet) + "decision: {min_confidence: 1.5}\n").find("decision.min_confidence: 1.5 is outside"),
            std::string::npos);
}

TEST(SegmenterSpec, ClassBiasesOffsetTheirClassesOnTopOfTheDynamicBias) {
  const SegmenterSpec spec = parse_segmenter_spec(
      std::string(kRangeNet) + "decision: {dynamic_bias: 2, class_bias: {building: 0.5, person: -0.25}}\n",
      "/models/m.yaml");
  const auto offsets = decision_offsets(spec);
  ASSERT_EQ(offsets.size(), spec.classes.size());
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    const auto id = spec.classes[k];
    const float expected = id == cls::kBuilding ? 0.5f
                           : id == cls::kPerson ? 1.75f
                           : (id == cls::kBicyclist || id == cls::kMotorcyclist) ? 2.0f
                                                                                  : 0.0f;
    EXPECT_EQ(offsets[k], expected) << class_name(id);
  }
  const SegmenterSpec again = parse_segmenter_spec(segmenter_spec_yaml(spec, "/models"), "/models/m.yaml");
  EXPECT_EQ(decision_offsets(again), offsets) << segmenter_spec_yaml(spec, "/models");

  const SegmenterSpec only = parse_segmenter_spec(std::string(kRangeNet) + "decision: {class_bias: {fence: 1}}\n",
                                                  "/models/m.yaml");
  EXPECT_EQ(only.dynamic_bias, 0.0);
  const auto only_offsets = decision_offsets(only);
  EXPECT_EQ(std::count(only_offsets.begin(), only_offsets.end(), 1.0f), 1);
  EXPECT_EQ(std::count(only_offsets.begin(), only_offsets.end(), 0.0f), static_cast<long>(only_offsets.size()) - 1);
  const SegmenterSpec zero = parse_segmenter_spec(std::string(kRangeNet) + "decision: {class_bias: {fence: 0}}\n",
                                                  "/models/m.yaml");
  EXPECT_TRUE(decision_offsets(zero).empty()) << "every offset 0: the plain argmax";

  EXPECT_NE(error_of(std::string(kRangeNet) + "decision: {class_bias: {house: 1}}\n")
                .find("decision.class_bias.house: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kRangeNet) + "decision: {class_bias: {unlabeled: 1}}\n")
                .find("decision.class_bias.unlabeled: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kRangeNet) + "decision: {class_bias: {fence: 21}}\n")
                .find("decision.class_bias.fence: 21 is outside"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kRangeNet) + "decision: {class_bias: {fence: 1, fence: 2}}\n")
                .find("'decision.class_bias.fence' is given twice (lines 13 and 13)"),
            std::string::npos);
}

TEST(SegmenterSpec, ErrorsNameTheFileAndTheKey) {
  EXPECT_NE(error_of("format: other 2\n").find("/models/m.yaml: format: expected 'saloam-segmenter 1'"), std::string::npos);
  // A list where a key belongs (found by fuzzing: it ended the program).
  EXPECT_NE(error_of(replaced(kSegNet, "stem_stride:", "[31, 64]: 1, stem_stride:"))
                .find("/models/m.yaml: line 2: a key in 'network' that is not a name (a list or a map)"),
            std::string::npos)
      << error_of(replaced(kSegNet, "stem_stride:", "[31, 64]: 1, stem_stride:"));
  EXPECT_NE(error_of(replaced(kSegNet, "columns: 1024", "columns: 1024\n  colums: 3")).find("projection.colums: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kSegNet, "columns: 1024", "columns: 1024\n  columns: 512")).find("'projection.columns' is given twice (lines 6 and 7)"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kSegNet, "columns: 1024", "columns: 5")).find("projection.columns: 5 is outside [16, 16384]"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kSegNet, "columns: 1024", "columns: wide")).find("projection.columns: 'wide' is not a number"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kSegNet, "stds: [8, 0.2, 0.5]", "stds: [8, 0, 0.5]")).find("projection.stds"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kSegNet, "means: [10, 0.3, 0.5]", "means: [10, .nan, 0.5]")).find("projection.means"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kSegNet, "means: [10, 0.3, 0.5]", "means: [10, 0.3]")).find("one value per channel"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kSegNet, "remission, mask", "remission, colour")).find("unknown channel 'colour'"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kSegNet, "[unlabeled, car,", "[car, unlabeled,")).find("must be unlabeled"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kSegNet, "road, building", "road, bilding")).find("'bilding' is not a SemanticKITTI class"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kSegNet, "window: 3", "window: 4")).find("knn.window: must be odd"), std::string::npos);
  EXPECT_NE(error_of(replaced(kSegNet, "beams: [16, 32, 64]", "beams: [2]")).find("projection.beams"), std::string::npos);
  EXPECT_NE(error_of(replaced(kRangeNet, "fov_down_deg: -25.0", "fov_down_deg: 5.0")).find("below fov_up_deg"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kRangeNet, "type: torchscript, file: rangenet.pt",
                              "type: torchscript, file: rangenet.pt, widths: [1, 2, 3]"))
                .find("network.widths: only for type segnet"),
            std::string::npos);
  EXPECT_NE(error_of("format: [unclosed\n").find("not valid YAML"), std::string::npos);
}

TEST(SegmenterSpec, MalformedYamlEndsWithAnErrorNotOutOfMemory) {
  // Found by the segmenter_spec fuzzer (fuzz/regressions/segmenter_spec/):
  // yaml-cpp's LoadAll on a flow sequence cut at its start took 5 GB and
  // more without end; the documents are counted first (load_yaml_document).
  const std::string yaml = ", remission], means:6\n  channels: [range, x]\nclasses: [unlabeled, car]\n";
  EXPECT_NE(error_of(yaml).find("/models/m.yaml: not valid YAML"), std::string::npos) << error_of(yaml);
}

TEST(SegmenterSpec, ReadsOnlySmallRegularFiles) {
  testing::TempDir dir;
  EXPECT_NE(testing::input_error_of([&] { (void)read_segmenter_spec(dir / "missing.yaml"); }).find("not found"),
            std::string::npos);
  EXPECT_NE(testing::input_error_of([&] { (void)read_segmenter_spec(dir.path()); }).find("directory"), std::string::npos);
  {
    std::ofstream big(dir / "big.yaml");
    big << "format: saloam-segmenter 1\n# " << std::string(2 << 20, 'x') << '\n';
  }
  EXPECT_NE(testing::input_error_of([&] { (void)read_segmenter_spec(dir / "big.yaml"); })
                .find("more than a segmentation model description may have"),
            std::string::npos);
  EXPECT_NE(testing::input_error_of([&] { (void)read_segmenter_spec("/dev/zero"); }).find("not a regular file"),
            std::string::npos);
  {
    std::ofstream two(dir / "two.yaml");
    two << kSegNet << "\n---\n" << kSegNet;
  }
  EXPECT_NE(testing::input_error_of([&] { (void)read_segmenter_spec(dir / "two.yaml"); }).find("holds 2 YAML documents"),
            std::string::npos);
  {
    std::ofstream ok(dir / "ok.yaml");
    ok << kSegNet;
  }
  EXPECT_EQ(read_segmenter_spec(dir / "ok.yaml").network.weights, (dir / "weights/model.pt").string());
}

}  // namespace
}  // namespace saloam
