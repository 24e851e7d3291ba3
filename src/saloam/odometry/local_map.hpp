#pragma once
// The semantic local map (paper Sec. III-B): edge and planar features of the
// last N_m frames in the world frame, split by class, each class with its own
// kd-tree so that a feature is matched only against map points of its class.
// Also the (semantic) voxel downsampling used for features and submaps.

#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <nanoflann.hpp>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/odometry/features.hpp"

namespace saloam {

/// Voxel edge length per class index; all equal in label-agnostic mode.
using ClassVoxelSizes = std::array<double, kNumClassIndices>;

/// Per-class voxel sizes from the config: `class_voxel_size` with semantics,
/// the plain `voxel_size` for every class without.
ClassVoxelSizes class_voxel_sizes(const OdometryConfig& config);
/// Per-class residual weights w^l (Eq. 2); all 1 without semantics.
std::array<double, kNumClassIndices> class_weights(const OdometryConfig& config);

/// Keeps the first point of every occupied voxel, voxels of each class apart
/// (a pole's points never merge into the road's voxel).
FeatureCloud voxel_downsample(const FeatureCloud& cloud, const ClassVoxelSizes& voxel_size);

/// Points of one class with a kd-tree over them.
class ClassSubmap {
 public:
  ClassSubmap();
  ClassSubmap(const ClassSubmap&) = delete;
  ClassSubmap& operator=(const ClassSubmap&) = delete;

  void rebuild(std::vector<Eigen::Vector3d> points);
  [[nodiscard]] const std::vector<Eigen::Vector3d>& points() const { return points_; }
  [[nodiscard]] std::size_t size() const { return points_.size(); }
  /// Up to k nearest neighbours (indices into points(), squared distances ascending).
  std::size_t nearest(const Eigen::Vector3d& query, std::size_t k, std::uint32_t* indices,
                      double* squared_distances) const;

  // nanoflann dataset adaptor interface
  [[nodiscard]] std::size_t kdtree_get_point_count() const { return points_.size(); }
  [[nodiscard]] double kdtree_get_pt(std::size_t i, std::size_t dim) const { return points_[i][static_cast<int>(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }

 private:
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, ClassSubmap>,
                                                   ClassSubmap, 3, std::uint32_t>;
  std::vector<Eigen::Vector3d> points_;
  std::unique_ptr<Tree> tree_;
};

/// Integer voxel coordinates plus class: the key of semantic voxel grids.
struct VoxelKey {
  std::int32_t x, y, z;
  std::int32_t c;
  bool operator==(const VoxelKey&) const = default;
};
struct VoxelKeyHash {
  std::size_t operator()(const VoxelKey& k) const {
    return (static_cast<std::size_t>(k.x) * 73856093u) ^ (static_cast<std::size_t>(k.y) * 19349669u) ^
           (static_cast<std::size_t>(k.z) * 83492791u) ^ (static_cast<std::size_t>(k.c) * 2654435761u);
  }
};

class SemanticLocalMap {
 public:
  SemanticLocalMap(int max_frames, ClassVoxelSizes voxel_size);

  /// Adds one frame's features (already in the world frame), drops the oldest
  /// beyond N_m and rebuilds the per-class submaps (edge and planar trees as
  /// two TBB tasks with `parallel`).
  void add_frame(const FeatureCloud& edges_world, const FeatureCloud& planars_world, bool parallel = false);
  [[nodiscard]] bool empty() const { return frame_count_ == 0; }
  [[nodiscard]] const ClassSubmap& edges(ClassIndex c) const { return *edge_maps_[c]; }
  [[nodiscard]] const ClassSubmap& planars(ClassIndex c) const { return *planar_maps_[c]; }
  [[nodiscard]] std::size_t num_edge_points() const;
  [[nodiscard]] std::size_t num_planar_points() const;

 private:
  // Voxel grid kept incrementally: each voxel holds the newest point that
  // fell into it and the frame it came from; a frame's voxels are released
  // when it leaves the window (unless a newer frame took them over).
  struct Voxel {
    Eigen::Vector3d point;
    std::uint64_t frame;
  };
  struct Grid {
    std::unordered_map<VoxelKey, Voxel, VoxelKeyHash> voxels;
    std::deque<std::vector<VoxelKey>> frame_keys;  ///< keys written by each frame in the window
  };
  void insert(Grid& grid, const FeatureCloud& cloud, std::uint64_t frame);
  void evict_oldest(Grid& grid);
  void rebuild_trees(const Grid& grid, std::array<std::unique_ptr<ClassSubmap>, kNumClassIndices>& maps) const;
  [[nodiscard]] VoxelKey key_of(const Eigen::Vector3d& p, ClassIndex c) const;

  int max_frames_;
  ClassVoxelSizes voxel_size_;
  std::uint64_t frame_count_ = 0;
  Grid edge_grid_;
  Grid planar_grid_;
  std::array<std::unique_ptr<ClassSubmap>, kNumClassIndices> edge_maps_;
  std::array<std::unique_ptr<ClassSubmap>, kNumClassIndices> planar_maps_;
};

}  // namespace saloam
