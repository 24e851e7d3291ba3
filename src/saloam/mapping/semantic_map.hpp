#pragma once
// A global semantic map: labelled scans accumulated in a voxel hash, one
// point per voxel (the centroid of its points) with the majority class.
// Dynamic classes (moving-*, person, ...) are left out so that the map holds
// the static world. Used for the map output of a run and for its pictures.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <tsl/robin_map.h>

#include "saloam/core/hash.hpp"
#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"

namespace saloam {

struct SemanticMapOptions {
  double voxel_size{};          ///< [m] map resolution (slam.map_voxel_size)
  double max_range = 60.0;      ///< [m] farther returns are noisy and sparse: skipped
  bool skip_dynamic = true;     ///< leave out moving objects and people
  bool skip_unlabeled = false;  ///< leave out class 0 (unlabeled) points

  /// The resolution from the configuration, which holds its default.
  static SemanticMapOptions from_config(const SlamConfig& config);
};

class SemanticMap {
 public:
  explicit SemanticMap(SemanticMapOptions options);

  /// Adds a scan given in its sensor frame, with T_world<-sensor.
  void insert(const LabelledCloud& scan, const Pose& world_from_sensor);

  /// One point per voxel: centroid, majority class, mean remission, the
  /// instance id most seen with that class. `has_labels` is true when any
  /// inserted scan had labels.
  [[nodiscard]] LabelledCloud to_cloud() const;
  [[nodiscard]] std::size_t num_voxels() const { return voxels_.size(); }
  [[nodiscard]] const SemanticMapOptions& options() const { return options_; }

 private:
  struct Voxel {
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    float remission_sum = 0.0f;
    std::uint32_t count = 0;
    // Small class histogram: the few classes seen in one voxel.
    std::uint16_t labels[4] = {0, 0, 0, 0};
    std::uint16_t instances[4] = {0, 0, 0, 0};
    std::uint32_t votes[4] = {0, 0, 0, 0};
  };
  struct KeyHash {
    std::size_t operator()(const Eigen::Vector3i& k) const {
      // Spatial hash mixed down to the low bits, which the open-addressing
      // table indexes its buckets by.
      std::uint64_t h = static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.x())) * 73856093u ^
                        static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.y())) * 19349669u ^
                        static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.z())) * 83492791u;
      return static_cast<std::size_t>(fold_to_low_bits(h));
    }
  };

  SemanticMapOptions options_;
  bool has_labels_ = false;
  // Voxels in insertion order, found by key through a compact index (the
  // global map holds millions: an open-addressing table of whole voxels at
  // its load factor would take several times their size).
  tsl::robin_map<Eigen::Vector3i, std::uint32_t, KeyHash> index_;
  std::vector<Eigen::Vector3i> keys_;
  std::vector<Voxel> voxels_;
};

}  // namespace saloam
