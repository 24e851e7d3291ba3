#include "saloam/odometry/local_map.hpp"

#include <cmath>
#include <unordered_set>

#include "saloam/core/semantic_classes.hpp"

namespace saloam {

ClassVoxelSizes class_voxel_sizes(const OdometryConfig& config) {
  ClassVoxelSizes sizes{};
  for (int c = 0; c < kNumClassIndices; ++c) {
    sizes[c] = config.use_semantics
                   ? class_value(config.class_voxel_size, from_learning_class(static_cast<std::uint8_t>(c)),
                                 config.voxel_size)
                   : config.voxel_size;
  }
  return sizes;
}

std::array<double, kNumClassIndices> class_weights(const OdometryConfig& config) {
  std::array<double, kNumClassIndices> w{};
  for (int c = 0; c < kNumClassIndices; ++c) {
    w[c] = config.use_semantics
               ? class_value(config.class_weight, from_learning_class(static_cast<std::uint8_t>(c)), 1.0)
               : 1.0;
  }
  return w;
}

namespace {
struct VoxelKey {
  std::int32_t x, y, z;
  std::int32_t c;
  bool operator==(const VoxelKey&) const = default;
};
struct VoxelHash {
  std::size_t operator()(const VoxelKey& k) const {
    return (static_cast<std::size_t>(k.x) * 73856093u) ^ (static_cast<std::size_t>(k.y) * 19349669u) ^
           (static_cast<std::size_t>(k.z) * 83492791u) ^ (static_cast<std::size_t>(k.c) * 2654435761u);
  }
};
}  // namespace

FeatureCloud voxel_downsample(const FeatureCloud& cloud, const ClassVoxelSizes& voxel_size) {
  FeatureCloud out;
  out.points.reserve(cloud.size());
  out.classes.reserve(cloud.size());
  out.sweep_time.reserve(cloud.size());
  std::unordered_set<VoxelKey, VoxelHash> occupied;
  occupied.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double inv = 1.0 / voxel_size[cloud.classes[i]];
    const Eigen::Vector3d& p = cloud.points[i];
    const VoxelKey key{static_cast<std::int32_t>(std::floor(p.x() * inv)),
                       static_cast<std::int32_t>(std::floor(p.y() * inv)),
                       static_cast<std::int32_t>(std::floor(p.z() * inv)), cloud.classes[i]};
    if (occupied.insert(key).second) out.push_back(p, cloud.classes[i], cloud.sweep_time[i]);
  }
  return out;
}

ClassSubmap::ClassSubmap() = default;

void ClassSubmap::rebuild(std::vector<Eigen::Vector3d> points) {
  points_ = std::move(points);
  tree_.reset();
  if (points_.empty()) return;
  tree_ = std::make_unique<Tree>(3, *this, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree_->buildIndex();
}

std::size_t ClassSubmap::nearest(const Eigen::Vector3d& query, std::size_t k, std::uint32_t* indices,
                                 double* squared_distances) const {
  if (!tree_) return 0;
  return tree_->knnSearch(query.data(), k, indices, squared_distances);
}

SemanticLocalMap::SemanticLocalMap(int max_frames, ClassVoxelSizes voxel_size)
    : max_frames_(std::max(1, max_frames)), voxel_size_(voxel_size) {
  for (auto& m : edge_maps_) m = std::make_unique<ClassSubmap>();
  for (auto& m : planar_maps_) m = std::make_unique<ClassSubmap>();
}

void SemanticLocalMap::add_frame(FeatureCloud edges_world, FeatureCloud planars_world) {
  frames_.push_back(Frame{std::move(edges_world), std::move(planars_world)});
  while (static_cast<int>(frames_.size()) > max_frames_) frames_.pop_front();
  rebuild();
}

void SemanticLocalMap::rebuild() {
  // Rebuilding from the frame list is simpler and, measured with
  // bench_odometry (BM_LocalMapUpdate), a few ms per frame: cheaper than
  // an incremental tree, whose queries degrade as points are added/removed.
  auto build = [&](auto member, auto& maps) {
    FeatureCloud all;
    for (const auto& f : frames_) {
      const FeatureCloud& src = f.*member;
      all.points.insert(all.points.end(), src.points.begin(), src.points.end());
      all.classes.insert(all.classes.end(), src.classes.begin(), src.classes.end());
      all.sweep_time.insert(all.sweep_time.end(), src.sweep_time.begin(), src.sweep_time.end());
    }
    // Newest frames first so that the kept point of a voxel is the freshest.
    std::reverse(all.points.begin(), all.points.end());
    std::reverse(all.classes.begin(), all.classes.end());
    std::reverse(all.sweep_time.begin(), all.sweep_time.end());
    const FeatureCloud down = voxel_downsample(all, voxel_size_);
    std::array<std::vector<Eigen::Vector3d>, kNumClassIndices> per_class;
    for (std::size_t i = 0; i < down.size(); ++i) per_class[down.classes[i]].push_back(down.points[i]);
    for (int c = 0; c < kNumClassIndices; ++c) maps[c]->rebuild(std::move(per_class[c]));
  };
  build(&Frame::edges, edge_maps_);
  build(&Frame::planars, planar_maps_);
}

std::size_t SemanticLocalMap::num_edge_points() const {
  std::size_t n = 0;
  for (const auto& m : edge_maps_) n += m->size();
  return n;
}
std::size_t SemanticLocalMap::num_planar_points() const {
  std::size_t n = 0;
  for (const auto& m : planar_maps_) n += m->size();
  return n;
}

}  // namespace saloam
