#include "saloam/odometry/local_map.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tsl/robin_set.h>

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

VoxelKey voxel_key(const Eigen::Vector3d& p, ClassIndex c, double cell_size) {
  const double inv = 1.0 / cell_size;
  return VoxelKey{static_cast<std::int32_t>(std::floor(p.x() * inv)), static_cast<std::int32_t>(std::floor(p.y() * inv)),
                  static_cast<std::int32_t>(std::floor(p.z() * inv)), c};
}

FeatureCloud voxel_downsample(const FeatureCloud& cloud, const ClassVoxelSizes& voxel_size) {
  FeatureCloud out;
  out.points.reserve(cloud.size());
  out.classes.reserve(cloud.size());
  out.sweep_time.reserve(cloud.size());
  tsl::robin_set<VoxelKey, VoxelKeyHash> occupied;
  occupied.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const ClassIndex c = cloud.classes[i];
    if (occupied.insert(voxel_key(cloud.points[i], c, voxel_size[c])).second) {
      out.push_back(cloud.points[i], c, cloud.sweep_time[i]);
    }
  }
  return out;
}

NeighbourGrid::NeighbourGrid(double max_radius) : cell_size_(2.0 * max_radius) {
  if (!(max_radius > 0.0)) throw std::invalid_argument("NeighbourGrid: the search radius must be positive");
}

void NeighbourGrid::insert(const Eigen::Vector3d& p, ClassIndex c) {
  cells_[voxel_key(p, c, cell_size_)].push_back(p);
  ++class_size_[c];
  ++size_;
}

bool NeighbourGrid::erase(const Eigen::Vector3d& p, ClassIndex c) {
  const auto it = cells_.find(voxel_key(p, c, cell_size_));
  if (it == cells_.end()) return false;
  auto& cell = it.value();
  const auto found = std::find(cell.begin(), cell.end(), p);
  if (found == cell.end()) return false;
  *found = cell.back();  // order within a cell does not matter
  cell.pop_back();
  if (cell.empty()) cells_.erase(it);
  --class_size_[c];
  --size_;
  return true;
}

int NeighbourGrid::nearest(const Eigen::Vector3d& q, ClassIndex c, int k, double radius, Eigen::Vector3d* points,
                           double* squared_distances) const {
  if (k <= 0 || class_size_[c] == 0) return 0;
  radius = std::min(radius, max_radius());
  const VoxelKey own = voxel_key(q, c, cell_size_);
  // Per axis: the neighbour cell on the side of the nearer face, and the
  // distance from q to that face (the ball reaches no other cell).
  std::array<int, 3> side{};
  Eigen::Vector3d face;
  const std::array<std::int32_t, 3> cell{own.x, own.y, own.z};
  for (int a = 0; a < 3; ++a) {
    const double below = q[a] - cell[static_cast<std::size_t>(a)] * cell_size_;
    side[static_cast<std::size_t>(a)] = below < 0.5 * cell_size_ ? -1 : 1;
    face[a] = below < 0.5 * cell_size_ ? below : cell_size_ - below;
  }
  double bound = radius * radius;  // squared: the radius, then the k-th best distance
  int found = 0;
  // Own cell first, then faces, edges, the corner: near cells fill the k best
  // early, so that farther cells are skipped.
  static constexpr std::array<std::array<int, 3>, 8> kOrder{
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}}};
  for (const auto& use : kOrder) {
    double box = 0.0;  // squared distance from q to the neighbour cell
    for (int a = 0; a < 3; ++a) {
      if (use[static_cast<std::size_t>(a)]) box += face[a] * face[a];
    }
    if (box > bound) continue;
    const auto it = cells_.find(VoxelKey{own.x + use[0] * side[0], own.y + use[1] * side[1], own.z + use[2] * side[2], c});
    if (it == cells_.end()) continue;
    for (const Eigen::Vector3d& p : it->second) {
      const double d2 = (p - q).squaredNorm();
      if (d2 > bound || (found == k && d2 >= squared_distances[k - 1])) continue;
      // Insertion into the sorted k best.
      int j = found < k ? found++ : k - 1;
      for (; j > 0 && squared_distances[j - 1] > d2; --j) {
        squared_distances[j] = squared_distances[j - 1];
        points[j] = points[j - 1];
      }
      squared_distances[j] = d2;
      points[j] = p;
      if (found == k) bound = squared_distances[k - 1];
    }
  }
  return found;
}

MapVoxelPoint map_voxel_point(const OdometryConfig& config) {
  return config.local_map_point == "newest" ? MapVoxelPoint::kNewest : MapVoxelPoint::kFirst;
}

SemanticLocalMap::SemanticLocalMap(int max_frames, ClassVoxelSizes voxel_size, double search_radius,
                                   MapVoxelPoint keep)
    : max_frames_(std::max(1, max_frames)),
      voxel_size_(voxel_size),
      keep_(keep),
      edges_(search_radius),
      planars_(search_radius) {}

SemanticLocalMap SemanticLocalMap::from_config(const OdometryConfig& config) {
  return SemanticLocalMap(config.local_map_frames, class_voxel_sizes(config), config.max_correspondence_distance,
                          map_voxel_point(config));
}

void SemanticLocalMap::insert(Layer& layer, const FeatureCloud& cloud, std::uint64_t frame) {
  std::vector<VoxelKey> keys;
  keys.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const ClassIndex c = cloud.classes[i];
    const Eigen::Vector3d& p = cloud.points[i];
    const VoxelKey key = voxel_key(p, c, voxel_size_[c]);
    auto [it, inserted] = layer.voxels.try_emplace(key, Voxel{p, frame});
    if (!inserted) {
      if (it->second.frame == frame) continue;  // the first point of this frame stays
      if (keep_ == MapVoxelPoint::kFirst) {
        it.value().frame = frame;
        keys.push_back(key);
        continue;
      }
      layer.points.erase(it->second.point, c);
      it.value() = Voxel{p, frame};
    }
    layer.points.insert(p, c);
    keys.push_back(key);
  }
  layer.frame_keys.push_back(std::move(keys));
}

void SemanticLocalMap::evict_oldest(Layer& layer) {
  const std::uint64_t oldest = frame_count_ - layer.frame_keys.size();
  for (const auto& key : layer.frame_keys.front()) {
    const auto it = layer.voxels.find(key);
    if (it != layer.voxels.end() && it->second.frame == oldest) {
      layer.points.erase(it->second.point, static_cast<ClassIndex>(key.c));
      layer.voxels.erase(it);
    }
  }
  layer.frame_keys.pop_front();
}

void SemanticLocalMap::add_frame(const FeatureCloud& edges_world, const FeatureCloud& planars_world) {
  const std::uint64_t frame = frame_count_++;
  for (auto [layer, cloud] : {std::pair{&edges_, &edges_world}, std::pair{&planars_, &planars_world}}) {
    insert(*layer, *cloud, frame);
    while (static_cast<int>(layer->frame_keys.size()) > max_frames_) evict_oldest(*layer);
  }
}

}  // namespace saloam
