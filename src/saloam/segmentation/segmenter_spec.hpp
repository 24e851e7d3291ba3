#pragma once
// The description of a segmentation model (a YAML file beside its weights):
// which network, the projection it was trained with, its classes and the
// clean-up of its output. saloam's own models and networks trained
// elsewhere (RangeNet++, SalsaNext, Cylinder3D exported to TorchScript) are
// described the same way; docs/segmentation.md explains every key.
//
//   format: saloam-segmenter 1
//   network: {type: segnet | torchscript, file: WEIGHTS,
//             widths: [16, 32, 64], stem_stride: 4, context_blocks: 2}   # segnet only
//   projection:
//     rows: ring | N            # ring: one row per beam; N: rows by elevation
//     beams: [16, 32, 64]       # rows: ring: the beam counts the model accepts
//     fov_up_deg: 3.0           # rows: N only (RangeNet++: 3 / -25)
//     fov_down_deg: -25.0
//     columns: 2048
//     channels: [range, x, y, z, remission, mask]
//     means: [...]              # one per channel
//     stds: [...]               # one per channel, > 0
//   classes: semantickitti | [unlabeled, car, ...]   # output index -> class name
//   knn: {k: 5, window: 5, cutoff: 1.0, sigma: 1.0}
//   decision: {dynamic_bias: 0.0, class_bias: {building: 0.5}, min_confidence: 0.0}   # optional, each key too
//
// Every value is range-checked; an error names the file and the key.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "saloam/segmentation/knn_labels.hpp"
#include "saloam/segmentation/network_runner.hpp"
#include "saloam/segmentation/range_projection.hpp"

namespace saloam {

inline constexpr std::string_view kSegmenterFormat = "saloam-segmenter 1";

struct SegmenterSpec {
  std::filesystem::path file;       ///< the description this came from (for messages)
  NetworkSpec network;              ///< weights: an absolute path
  ProjectionSpec projection;
  std::vector<int> beams;           ///< RowMode::kRing: the beam counts (image rows) the model accepts
  std::vector<std::uint16_t> classes;  ///< network output index -> raw SemanticKITTI id
  KnnOptions knn;
  /// Added to the logits of the dynamic classes (person, bicyclist,
  /// motorcyclist and the moving-* ones, which the odometry drops) before
  /// the argmax. The odometry's costs are not symmetric: a walking person
  /// called a pole becomes a pole axis that moves and pulls the scans with
  /// it, while a pole called a person only loses one constraint; a bias > 0
  /// is the decision that weighs the first error more (docs/segmentation.md).
  double dynamic_bias = 0.0;
  /// Added to the logit of single classes (raw id, offset) before the
  /// argmax, after dynamic_bias: the same decision for other unequal costs,
  /// e.g. a building point called vegetation costs the odometry a plane,
  /// while vegetation called building is mostly refused by the plane's
  /// orientation check (docs/segmentation.md, "The decision").
  std::vector<std::pair<std::uint16_t, double>> class_bias;
  /// A point whose class the network gives a lower probability than this
  /// (Segmentation::confidence) is left unlabeled (raw id 0): 0 labels every
  /// point; self-training's teachers label only what they are sure of.
  double min_confidence = 0.0;
};

/// One offset per output class of `spec` (the dynamic ones get
/// spec.dynamic_bias, plus spec.class_bias's), or none when every offset is
/// 0: NetworkSpec::logit_offsets.
std::vector<float> decision_offsets(const SegmenterSpec& spec);

/// The 20 SemanticKITTI training classes in their learning order (0 =
/// unlabeled, 1 = car, ..., 19 = traffic-sign), as RangeNet++ and SalsaNext output them.
std::vector<std::uint16_t> semantickitti_learning_classes();

/// Reads and checks a model description; relative weight paths are relative
/// to the file. InputError naming the file and the key for anything wrong.
/// The weights file itself is not opened here.
SegmenterSpec read_segmenter_spec(const std::filesystem::path& file);
/// The same from text (`origin` names it in errors, and relative paths are
/// relative to origin's folder).
SegmenterSpec parse_segmenter_spec(std::string_view yaml_text, const std::filesystem::path& origin);
/// The description as YAML; the weights path is written relative to `folder`
/// when it lies there.
std::string segmenter_spec_yaml(const SegmenterSpec& spec, const std::filesystem::path& folder);

}  // namespace saloam
