#pragma once
// The semantic local map (paper Sec. III-B): edge and planar features of the
// last N_m frames in the world frame, kept per class, so that a feature is
// matched only against map points of its class. Also the (semantic) voxel
// downsampling used for features and submaps.
//
// The map is updated incrementally rather than rebuilt: points live in a
// hash of cubic cells (NeighbourGrid), so a neighbour query visits at most 8
// cells and a new frame costs only its own points. Measured against
// rebuilding per-class kd-trees every frame and against nanoflann's dynamic
// index (bench_odometry: BM_NeighbourGrid, BM_MapTreeRebuild,
// BM_MapTreeDynamic), it is the fastest, with the same neighbours.

#include <array>
#include <cstdint>
#include <deque>
#include <vector>

#include <Eigen/Core>
#include <tsl/robin_map.h>

#include "saloam/core/config.hpp"
#include "saloam/core/hash.hpp"
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

/// Integer cell coordinates plus class: the key of semantic voxel grids.
struct VoxelKey {
  std::int32_t x, y, z;
  std::int32_t c;
  bool operator==(const VoxelKey&) const = default;
};
struct VoxelKeyHash {
  std::size_t operator()(const VoxelKey& k) const {
    // Spatial hash mixed down to the low bits: open-addressing tables index
    // buckets by the low bits of the hash.
    std::uint64_t h = static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.x)) * 73856093u ^
                      static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.y)) * 19349669u ^
                      static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.z)) * 83492791u ^
                      static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.c)) * 2654435761u;
    return static_cast<std::size_t>(fold_to_low_bits(h));
  }
};
/// The cell of edge `cell_size` that contains p, for class c.
VoxelKey voxel_key(const Eigen::Vector3d& p, ClassIndex c, double cell_size);

/// Points of several classes with exact k-nearest-neighbour search within a
/// radius, among the points of one class.
///
/// Cells are twice the largest query radius: a ball of that radius around q
/// then lies within the 2 x 2 x 2 cells nearest q (on each axis, q's cell and
/// the neighbour on the side of the nearer face), so a query costs 8 hash
/// lookups instead of the 27 of radius-sized cells. Cells hold more points,
/// but scanning a short contiguous array is cheaper than a lookup.
class NeighbourGrid {
 public:
  /// `max_radius`: the largest radius `nearest` will be asked for [m].
  explicit NeighbourGrid(double max_radius);

  void insert(const Eigen::Vector3d& p, ClassIndex c);
  /// Removes one point equal to p (of class c); false if there is none.
  bool erase(const Eigen::Vector3d& p, ClassIndex c);

  /// Up to k nearest points of class c within `radius` of q (clamped to
  /// max_radius), nearest first: fills points[0..n) and squared_distances[0..n), returns n.
  int nearest(const Eigen::Vector3d& q, ClassIndex c, int k, double radius, Eigen::Vector3d* points,
              double* squared_distances) const;

  [[nodiscard]] double max_radius() const { return 0.5 * cell_size_; }
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] std::size_t size(ClassIndex c) const { return class_size_[c]; }
  /// Calls f(point, class) for every point, in no particular order.
  template <class F>
  void for_each(F&& f) const {
    for (const auto& [key, points] : cells_) {
      for (const Eigen::Vector3d& p : points) f(p, static_cast<ClassIndex>(key.c));
    }
  }

 private:
  double cell_size_;
  tsl::robin_map<VoxelKey, std::vector<Eigen::Vector3d>, VoxelKeyHash> cells_;
  std::array<std::size_t, kNumClassIndices> class_size_{};
  std::size_t size_ = 0;
};

/// Which point a local-map voxel keeps when a later frame observes it again.
enum class MapVoxelPoint {
  /// The first one: the map stays where the voxel was first registered, so a
  /// scan is aligned to the places it shares with scans far back and the
  /// drift grows only as fast as places leave the map (KISS-ICP's voxel map
  /// keeps first points too).
  kFirst,
  /// The newest one: the map follows the latest registrations (the map of
  /// "the last N_m frames" taken literally).
  kNewest,
};
/// From the config's `local_map_point` ("first" or "newest").
MapVoxelPoint map_voxel_point(const OdometryConfig& config);

class SemanticLocalMap {
 public:
  /// `max_frames` (N_m): a voxel leaves the map when the last N_m frames have
  /// not observed it. `search_radius`: the largest neighbour distance queries
  /// will ask for (the registration's max correspondence distance).
  SemanticLocalMap(int max_frames, ClassVoxelSizes voxel_size, double search_radius,
                   MapVoxelPoint keep = MapVoxelPoint::kFirst);
  /// The map the odometry configured by `config` uses.
  static SemanticLocalMap from_config(const OdometryConfig& config);

  /// Adds one frame's features (already in the world frame): a new class
  /// voxel takes the frame's first point in it; a voxel already in the map
  /// keeps its point or takes the frame's (see MapVoxelPoint) and counts as
  /// observed by this frame. Then voxels no frame of the last N_m observed leave.
  void add_frame(const FeatureCloud& edges_world, const FeatureCloud& planars_world);
  [[nodiscard]] bool empty() const { return frame_count_ == 0; }
  [[nodiscard]] const NeighbourGrid& edges() const { return edges_.points; }
  [[nodiscard]] const NeighbourGrid& planars() const { return planars_.points; }
  [[nodiscard]] std::size_t num_edge_points() const { return edges_.points.size(); }
  [[nodiscard]] std::size_t num_planar_points() const { return planars_.points.size(); }

 private:
  struct Voxel {
    Eigen::Vector3d point;
    std::uint64_t frame;  ///< the last frame that observed the voxel
  };
  /// One feature type: the downsampling voxels (which point represents each
  /// voxel, and since which frame) and the searchable points they hold.
  struct Layer {
    explicit Layer(double search_radius) : points(search_radius) {}
    tsl::robin_map<VoxelKey, Voxel, VoxelKeyHash> voxels;
    std::deque<std::vector<VoxelKey>> frame_keys;  ///< voxels observed by each frame in the window
    NeighbourGrid points;
  };
  void insert(Layer& layer, const FeatureCloud& cloud, std::uint64_t frame);
  void evict_oldest(Layer& layer);

  int max_frames_;
  ClassVoxelSizes voxel_size_;
  MapVoxelPoint keep_;
  std::uint64_t frame_count_ = 0;
  Layer edges_;
  Layer planars_;
};

}  // namespace saloam
