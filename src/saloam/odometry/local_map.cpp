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

NeighbourGrid::NeighbourGrid(double cell_size) : cell_size_(cell_size) {
  if (!(cell_size > 0.0)) throw std::invalid_argument("NeighbourGrid: cell size must be positive");
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

namespace {
// The 27 cells around a query, own cell first, then faces, edges, corners:
// near cells first fill the k best early, so that farther cells are skipped.
constexpr std::array<std::array<int, 3>, 27> kNeighbourCells = [] {
  std::array<std::array<int, 3>, 27> cells{};
  int n = 0;
  for (int nonzero = 0; nonzero <= 3; ++nonzero) {
    for (int x = -1; x <= 1; ++x) {
      for (int y = -1; y <= 1; ++y) {
        for (int z = -1; z <= 1; ++z) {
          if ((x != 0) + (y != 0) + (z != 0) == nonzero) cells[n++] = {x, y, z};
        }
      }
    }
  }
  return cells;
}();
}  // namespace

int NeighbourGrid::nearest(const Eigen::Vector3d& q, ClassIndex c, int k, double radius, Eigen::Vector3d* points,
                           double* squared_distances) const {
  if (k <= 0 || class_size_[c] == 0) return 0;
  // A radius beyond the cell size could miss points outside the 27 cells.
  radius = std::min(radius, cell_size_);
  const VoxelKey centre = voxel_key(q, c, cell_size_);
  // Distances from q to its cell's lower and upper faces along each axis.
  const Eigen::Vector3d cell_origin = Eigen::Vector3d(centre.x, centre.y, centre.z) * cell_size_;
  const Eigen::Vector3d below = q - cell_origin;
  const Eigen::Vector3d above = Eigen::Vector3d::Constant(cell_size_) - below;
  double bound = radius * radius;  // squared: the radius, then the k-th best distance
  int found = 0;
  for (const auto& offset : kNeighbourCells) {
    double box = 0.0;  // squared distance from q to the neighbour cell
    for (int a = 0; a < 3; ++a) {
      if (offset[a] < 0) box += below[a] * below[a];
      if (offset[a] > 0) box += above[a] * above[a];
    }
    if (box > bound) continue;
    const auto it = cells_.find(VoxelKey{centre.x + offset[0], centre.y + offset[1], centre.z + offset[2], c});
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
