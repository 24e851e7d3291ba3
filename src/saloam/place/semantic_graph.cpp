#include "saloam/place/semantic_graph.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numeric>

#include <nanoflann.hpp>

#include "saloam/core/hash.hpp"
#include "saloam/core/semantic_classes.hpp"

namespace saloam {
namespace {

constexpr std::array<std::string_view, kNumNodeClasses> kNodeClassNames{
    "car",      "truck", "other-vehicle", "sidewalk", "other-ground", "building",
    "fence",    "vegetation", "trunk",    "terrain",  "pole",         "traffic-sign"};

// ---------------------------------------------------------------- union-find
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0U); }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];  // path halving
      x = parent_[x];
    }
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (a > b) std::swap(a, b);
    parent_[b] = a;  // smaller root wins: deterministic
  }

 private:
  std::vector<std::uint32_t> parent_;
};

// ------------------------------------------------------ voxel hash (cells)
constexpr int kCellBits = 21;
constexpr std::int64_t kCellOffset = std::int64_t{1} << (kCellBits - 1);

inline std::uint64_t pack_cell(std::int64_t x, std::int64_t y, std::int64_t z) {
  const auto mask = (std::uint64_t{1} << kCellBits) - 1;
  return (static_cast<std::uint64_t>(x + kCellOffset) & mask) << (2 * kCellBits) |
         (static_cast<std::uint64_t>(y + kCellOffset) & mask) << kCellBits |
         (static_cast<std::uint64_t>(z + kCellOffset) & mask);
}

/// Open-addressing map from packed cell key to cell index (keys never 0 here
/// because of the offset; 0 marks an empty slot).
class CellTable {
 public:
  explicit CellTable(std::size_t cells) {
    std::size_t capacity = 16;
    while (capacity < 2 * cells) capacity <<= 1;
    keys_.assign(capacity, 0);
    values_.assign(capacity, 0);
    mask_ = capacity - 1;
  }
  void insert(std::uint64_t key, std::uint32_t value) {
    std::size_t slot = hash(key);
    while (keys_[slot] != 0) slot = (slot + 1) & mask_;
    keys_[slot] = key;
    values_[slot] = value;
  }
  [[nodiscard]] std::int64_t find(std::uint64_t key) const {
    std::size_t slot = hash(key);
    while (keys_[slot] != 0) {
      if (keys_[slot] == key) return values_[slot];
      slot = (slot + 1) & mask_;
    }
    return -1;
  }

 private:
  [[nodiscard]] std::size_t hash(std::uint64_t key) const {
    return static_cast<std::size_t>(fold_to_low_bits(key)) & mask_;
  }
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> values_;
  std::size_t mask_ = 0;
};

// ------------------------------------------------- kd-tree over a cluster
struct ClusterPoints {
  const LabelledCloud* cloud;
  const std::vector<std::uint32_t>* indices;
  [[nodiscard]] std::size_t kdtree_get_point_count() const { return indices->size(); }
  [[nodiscard]] float kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return cloud->points[(*indices)[i]][static_cast<Eigen::Index>(dim)];
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using ClusterTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, ClusterPoints>,
                                                        ClusterPoints, 3, std::uint32_t>;

struct Box {
  Eigen::Vector3f min = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f max = Eigen::Vector3f::Constant(std::numeric_limits<float>::lowest());
  [[nodiscard]] float distance_squared(const Eigen::Vector3f& p) const {
    const Eigen::Vector3f d = (min - p).cwiseMax(p - max).cwiseMax(0.0F);
    return d.squaredNorm();
  }
  [[nodiscard]] float distance_squared(const Box& o) const {
    const Eigen::Vector3f d = (min - o.max).cwiseMax(o.min - max).cwiseMax(0.0F);
    return d.squaredNorm();
  }
};

Box bounding_box(const LabelledCloud& cloud, const Cluster& c) {
  Box b;
  for (const auto i : c.points) {
    b.min = b.min.cwiseMin(cloud.points[i]);
    b.max = b.max.cwiseMax(cloud.points[i]);
  }
  return b;
}

/// Exact nearest-point distance of `query` to the points in `tree`, bounded:
/// query points are visited in order of their distance to the tree's box, and
/// the search stops once that lower bound exceeds the best distance found.
double bounded_cluster_distance(const LabelledCloud& cloud, const Cluster& query, const Box& tree_box,
                                const ClusterTree& tree, double max_distance) {
  const float limit_sq = static_cast<float>(max_distance * max_distance);
  std::vector<std::pair<float, std::uint32_t>> order;
  for (const auto i : query.points) {
    const float d = tree_box.distance_squared(cloud.points[i]);
    if (d <= limit_sq) order.emplace_back(d, i);
  }
  std::sort(order.begin(), order.end());
  float best = std::numeric_limits<float>::infinity();
  for (const auto& [bound, i] : order) {
    if (bound >= best) break;
    std::uint32_t nearest = 0;
    float d_sq = 0;
    tree.knnSearch(cloud.points[i].data(), 1, &nearest, &d_sq);
    best = std::min(best, d_sq);
  }
  const double d = std::sqrt(static_cast<double>(best));
  return d <= max_distance ? d : std::numeric_limits<double>::infinity();
}

}  // namespace

std::optional<int> node_class_of(std::uint16_t raw_label) {
  switch (to_learning_class(static_class(raw_label))) {
    case 1: return node_class::kCar;
    case 4: return node_class::kTruck;
    case 5: return node_class::kOtherVehicle;  // bus, on-rails, other-vehicle
    case 11: return node_class::kSidewalk;
    case 12: return node_class::kOtherGround;
    case 13: return node_class::kBuilding;
    case 14: return node_class::kFence;
    case 15: return node_class::kVegetation;
    case 16: return node_class::kTrunk;
    case 17: return node_class::kTerrain;
    case 18: return node_class::kPole;
    case 19: return node_class::kTrafficSign;
    default: return std::nullopt;  // road, parking, people, two-wheelers, unlabeled
  }
}

std::string_view node_class_name(int node_class) {
  if (node_class < 0 || node_class >= kNumNodeClasses) return "unknown";
  return kNodeClassNames[static_cast<std::size_t>(node_class)];
}

namespace {

/// Points binned into cubic cells: `keyed` holds (cell key, position in
/// indices) sorted by key, and cell c holds keyed[start[c] .. start[c + 1]).
struct CellBins {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  std::vector<std::uint32_t> start;
  [[nodiscard]] std::size_t cells() const { return start.size() - 1; }
  [[nodiscard]] std::uint64_t key(std::size_t c) const { return keyed[start[c]].first; }
};

CellBins bin_points(std::span<const Eigen::Vector3f> points, std::span<const std::uint32_t> indices, double cell) {
  CellBins bins;
  const std::size_t n = indices.size();
  bins.keyed.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3f& p = points[indices[k]];
    bins.keyed[k] = {pack_cell(static_cast<std::int64_t>(std::floor(p.x() / cell)),
                               static_cast<std::int64_t>(std::floor(p.y() / cell)),
                               static_cast<std::int64_t>(std::floor(p.z() / cell))),
                     static_cast<std::uint32_t>(k)};
  }
  std::sort(bins.keyed.begin(), bins.keyed.end());
  for (std::size_t k = 0; k < n; ++k)
    if (k == 0 || bins.keyed[k].first != bins.keyed[k - 1].first) bins.start.push_back(static_cast<std::uint32_t>(k));
  bins.start.push_back(static_cast<std::uint32_t>(n));
  return bins;
}

std::int64_t unpack_cell(std::uint64_t key, int shift) {
  const auto mask = (std::uint64_t{1} << kCellBits) - 1;
  return static_cast<std::int64_t>((key >> shift) & mask) - kCellOffset;
}

/// Whether a point of cell `a` and one of cell `b` are at most sqrt(tol_sq) apart.
bool cells_touch(std::span<const Eigen::Vector3f> points, std::span<const std::uint32_t> indices,
                 const CellBins& bins, std::uint32_t a, std::uint32_t b, float tol_sq) {
  for (std::uint32_t i = bins.start[a]; i < bins.start[a + 1]; ++i) {
    const Eigen::Vector3f& p = points[indices[bins.keyed[i].second]];
    for (std::uint32_t j = bins.start[b]; j < bins.start[b + 1]; ++j) {
      if ((points[indices[bins.keyed[j].second]] - p).squaredNorm() <= tol_sq) return true;
    }
  }
  return false;
}

/// Cells joined into components: each cell with every cell of the 5x5x5
/// block around it that holds a point within tolerance of one of its own.
DisjointSets connect_cells(std::span<const Eigen::Vector3f> points, std::span<const std::uint32_t> indices,
                           const CellBins& bins, float tol_sq) {
  const std::size_t num_cells = bins.cells();
  CellTable table(num_cells);
  for (std::size_t c = 0; c < num_cells; ++c) table.insert(bins.key(c), static_cast<std::uint32_t>(c));
  DisjointSets sets(num_cells);
  for (std::size_t a = 0; a < num_cells; ++a) {
    const std::uint64_t key = bins.key(a);
    const std::int64_t cx = unpack_cell(key, 2 * kCellBits), cy = unpack_cell(key, kCellBits), cz = unpack_cell(key, 0);
    for (int dx = -2; dx <= 2; ++dx)
      for (int dy = -2; dy <= 2; ++dy)
        for (int dz = -2; dz <= 2; ++dz) {
          // Visit each unordered pair of cells once (lexicographically positive offsets).
          if (dx < 0 || (dx == 0 && (dy < 0 || (dy == 0 && dz <= 0)))) continue;
          const std::int64_t b = table.find(pack_cell(cx + dx, cy + dy, cz + dz));
          if (b < 0) continue;
          const auto cb = static_cast<std::uint32_t>(b);
          if (sets.find(static_cast<std::uint32_t>(a)) == sets.find(cb)) continue;
          if (cells_touch(points, indices, bins, static_cast<std::uint32_t>(a), cb, tol_sq)) {
            sets.unite(static_cast<std::uint32_t>(a), cb);
          }
        }
  }
  return sets;
}

/// The components of min_size..max_size points as clusters of `indices`, in
/// order of their first input position; points in input order.
std::vector<std::vector<std::uint32_t>> components_in_input_order(std::span<const std::uint32_t> indices,
                                                                  const CellBins& bins, DisjointSets& sets,
                                                                  std::size_t min_size, std::size_t max_size) {
  const std::size_t n = indices.size(), num_cells = bins.cells();
  std::vector<std::uint32_t> cell_of(n);
  for (std::size_t c = 0; c < num_cells; ++c)
    for (std::uint32_t k = bins.start[c]; k < bins.start[c + 1]; ++k) cell_of[bins.keyed[k].second] = static_cast<std::uint32_t>(c);
  std::vector<std::uint32_t> root_size(num_cells, 0);
  for (std::size_t k = 0; k < n; ++k) ++root_size[sets.find(cell_of[k])];
  std::vector<std::vector<std::uint32_t>> clusters;
  std::vector<std::int64_t> cluster_of_root(num_cells, -1);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t root = sets.find(cell_of[k]);
    if (root_size[root] < min_size || root_size[root] > max_size) continue;
    if (cluster_of_root[root] < 0) {
      cluster_of_root[root] = static_cast<std::int64_t>(clusters.size());
      clusters.emplace_back();
      clusters.back().reserve(root_size[root]);
    }
    clusters[static_cast<std::size_t>(cluster_of_root[root])].push_back(indices[k]);
  }
  return clusters;
}

}  // namespace

std::vector<std::vector<std::uint32_t>> euclidean_clusters(std::span<const Eigen::Vector3f> points,
                                                           std::span<const std::uint32_t> indices,
                                                           double tolerance, std::size_t min_size,
                                                           std::size_t max_size) {
  if (indices.empty() || !(tolerance > 0)) return {};
  // Cells of edge tolerance / sqrt(3): two points in one cell are at most
  // `tolerance` apart, so a cell is connected without tests and only the
  // 5x5x5 block of cells around it can hold neighbours.
  const double cell = tolerance / std::sqrt(3.0) * (1.0 - 1e-9);
  const CellBins bins = bin_points(points, indices, cell);
  DisjointSets sets = connect_cells(points, indices, bins, static_cast<float>(tolerance * tolerance));
  return components_in_input_order(indices, bins, sets, min_size, max_size);
}

std::vector<Cluster> extract_clusters(const LabelledCloud& cloud, const GraphBuilderConfig& config) {
  // Points per node class; vehicle points with an instance id go by instance.
  std::array<std::vector<std::uint32_t>, kNumNodeClasses> geometric;
  std::array<std::map<std::uint16_t, std::vector<std::uint32_t>>, kNumNodeClasses> instances;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto nc = node_class_of(cloud.label[i]);
    if (!nc) continue;
    const auto index = static_cast<std::uint32_t>(i);
    const bool vehicle = *nc == node_class::kCar || *nc == node_class::kTruck || *nc == node_class::kOtherVehicle;
    if (config.use_instances && vehicle && cloud.instance[i] != 0)
      instances[static_cast<std::size_t>(*nc)][cloud.instance[i]].push_back(index);
    else
      geometric[static_cast<std::size_t>(*nc)].push_back(index);
  }
  std::vector<Cluster> clusters;
  for (int c = 0; c < kNumNodeClasses; ++c) {
    const auto uc = static_cast<std::size_t>(c);
    for (auto& [id, members] : instances[uc]) {
      if (members.size() <= config.min_instance_points) continue;
      clusters.push_back({c, std::move(members), Eigen::Vector3d::Zero()});
    }
    for (auto& members : euclidean_clusters(cloud.points, geometric[uc], config.tolerance[uc],
                                            config.min_cluster_size[uc], config.max_cluster_size))
      clusters.push_back({c, std::move(members), Eigen::Vector3d::Zero()});
  }
  for (auto& cluster : clusters) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto i : cluster.points) sum += cloud.points[i].cast<double>();
    cluster.centroid = sum / static_cast<double>(cluster.points.size());
  }
  return clusters;
}

double cluster_distance(const LabelledCloud& cloud, const Cluster& a, const Cluster& b, double max_distance) {
  const Cluster& small = a.points.size() <= b.points.size() ? a : b;
  const Cluster& large = a.points.size() <= b.points.size() ? b : a;
  const ClusterPoints data{&cloud, &large.points};
  const ClusterTree tree(3, data, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  return bounded_cluster_distance(cloud, small, bounding_box(cloud, large), tree, max_distance);
}

SemanticGraph build_semantic_graph(const LabelledCloud& cloud, const GraphBuilderConfig& config) {
  std::vector<Cluster> clusters = extract_clusters(cloud, config);
  if (clusters.size() > config.max_nodes) {
    // Deterministic cap: the largest clusters (ties: lower class, earlier cluster), original order kept.
    std::vector<std::size_t> order(clusters.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
      if (clusters[x].points.size() != clusters[y].points.size())
        return clusters[x].points.size() > clusters[y].points.size();
      return clusters[x].node_class < clusters[y].node_class;
    });
    order.resize(config.max_nodes);
    std::sort(order.begin(), order.end());
    std::vector<Cluster> kept;
    kept.reserve(order.size());
    for (const auto k : order) kept.push_back(std::move(clusters[k]));
    clusters = std::move(kept);
  }

  SemanticGraph graph;
  for (const auto& c : clusters) {
    graph.nodes.push_back(c.node_class);
    graph.centers.push_back(c.centroid);
  }
  // Edges: nearest points within edge_distance, weight 1 - d / edge_distance.
  const std::size_t n = clusters.size();
  std::vector<Box> boxes(n);
  for (std::size_t i = 0; i < n; ++i) boxes[i] = bounding_box(cloud, clusters[i]);
  std::vector<std::unique_ptr<ClusterPoints>> data(n);
  std::vector<std::unique_ptr<ClusterTree>> trees(n);  // built lazily, for the larger cluster of a pair
  const auto limit_sq = static_cast<float>(config.edge_distance * config.edge_distance);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      if (boxes[i].distance_squared(boxes[j]) > limit_sq) continue;
      const bool i_small = clusters[i].points.size() <= clusters[j].points.size();
      const std::size_t s = i_small ? i : j, l = i_small ? j : i;
      if (!trees[l]) {
        data[l] = std::make_unique<ClusterPoints>(ClusterPoints{&cloud, &clusters[l].points});
        trees[l] = std::make_unique<ClusterTree>(3, *data[l], nanoflann::KDTreeSingleIndexAdaptorParams(16));
      }
      const double d = bounded_cluster_distance(cloud, clusters[s], boxes[l], *trees[l], config.edge_distance);
      if (!std::isfinite(d)) continue;
      graph.edges.push_back({static_cast<int>(i), static_cast<int>(j)});
      graph.weights.push_back(1.0 - d / config.edge_distance);
    }
  return graph;
}

}  // namespace saloam
