#pragma once
// Emulated semantic segmentation: turns ground-truth labels into what a
// range-image network (RangeNet++-like, ~52 % mIoU on SemanticKITTI) would
// output (scored with eval/segmentation_score.hpp).

#include <cstdint>
#include <vector>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/eval/segmentation_score.hpp"
#include "saloam/sim/lidar.hpp"

namespace saloam {

struct LabelNoiseOptions {
  double boundary_flip = 0.8;    ///< chance (times the share of other classes around) that a point takes a neighbour's class
  int boundary_columns = 2;      ///< neighbourhood half width in columns
  double confusion_scale = 1.0;  ///< scales the per-class confusion rates
  double random_label = 0.01;    ///< chance of a uniformly random class
  int block_rings = 4, block_columns = 24;  ///< size of correlated error blobs in the range image
};

/// Network-like labels for a simulated scan (raw ids of the 19 learning
/// classes, no moving-* classes, instance 0), deterministic for a seed.
std::vector<std::uint16_t> emulate_segmentation(const SimulatedScan& scan, int beams, int columns,
                                                std::uint64_t seed, const LabelNoiseOptions& options = {});

}  // namespace saloam
