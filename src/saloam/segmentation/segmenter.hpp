#pragma once
// The first box of the paper's Fig. 2: raw point cloud P -> semantic cloud S.
// A Segmenter labels a scan with a range-image network: project the scan
// (range_projection.hpp), classify every pixel (the network, in the libtorch
// plugin: network_runner.hpp), carry the classes back to every point with
// the k-nearest-neighbour vote (knn_labels.hpp), and name them as
// SemanticKITTI raw class ids.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/scan/rings.hpp"
#include "saloam/segmentation/segmenter_spec.hpp"

namespace saloam {

/// File name of the plugin that runs the networks (built only with libtorch).
inline constexpr const char* kSegmentationPlugin = "libsaloam_segment_torch.so";

/// Loads the network plugin at `plugin` once per process (later calls reuse
/// it). InputError naming the file when it is missing (this saloam was built
/// without libtorch) or cannot be loaded.
void load_segmentation_plugin(const std::filesystem::path& plugin);

/// A segmented scan, one entry per point.
struct Segmentation {
  /// Raw SemanticKITTI class id; 0 (unlabeled) where the model's
  /// decision.min_confidence is not reached.
  std::vector<std::uint16_t> labels;
  /// Empty unless asked for: how sure the network is of each point's class,
  /// its softmax probability at the point's own pixel (0 for points without
  /// a class). The kNN vote can give a point another class than its pixel's
  /// (at boundaries): the probability of that class there is low, as it
  /// should be.
  std::vector<float> confidence;
};

class Segmenter {
 public:
  /// Opens the network of `spec` in the plugin at `plugin`. `rings` says how
  /// rings are recovered for ring projections (the run's feature settings:
  /// beams, sweep direction). InputError naming the file for a missing or
  /// corrupt network or one that does not fit the description.
  Segmenter(SegmenterSpec spec, const std::filesystem::path& plugin, FeatureConfig rings = {});
  /// With a network already open (the trainer's, in-process).
  Segmenter(SegmenterSpec spec, std::unique_ptr<NetworkRunner> runner, FeatureConfig rings = {});
  ~Segmenter();
  Segmenter(const Segmenter&) = delete;
  Segmenter& operator=(const Segmenter&) = delete;

  /// Raw SemanticKITTI class id of every point. One call at a time per
  /// Segmenter; the result does not depend on how many Segmenters run at
  /// once. InputError naming the model when the scan does not fit it (beam
  /// count, or a network that rejects the image).
  [[nodiscard]] std::vector<std::uint16_t> labels(const LabelledCloud& cloud) const;
  /// The labels and, with `confidence`, each point's confidence (the same
  /// labels as labels()).
  [[nodiscard]] Segmentation segment(const LabelledCloud& cloud, bool confidence) const;
  /// The network's class index (0 .. classes - 1, spec().classes names
  /// them) of every point, with the rings already known (ring projections).
  [[nodiscard]] std::vector<std::int16_t> output_classes(const LabelledCloud& cloud, const std::vector<std::int16_t>& rings,
                                                         int beams) const;

  [[nodiscard]] const SegmenterSpec& spec() const { return spec_; }

 private:
  void check_beams(int beams) const;
  struct PointClasses {
    std::vector<std::int16_t> classes;  ///< the network's class index per point
    std::vector<float> confidence;      ///< empty unless asked for
  };
  [[nodiscard]] PointClasses point_output(const LabelledCloud& cloud, const std::vector<std::int16_t>& rings, int beams,
                                          bool confidence) const;

  SegmenterSpec spec_;
  FeatureConfig ring_config_;
  std::unique_ptr<NetworkRunner> runner_;
};

}  // namespace saloam
