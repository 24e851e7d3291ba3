#pragma once
// Semantic graphs of single scans (SGPR, Kong et al. IROS 2020, Sec. III-A):
// one node per object or stuff cluster, at the cluster's centroid, carrying
// one of 12 node classes; edges between clusters whose nearest points are
// close. The network uses only node classes and centres; edges are kept for
// exchange with the Python original.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/types.hpp"

namespace saloam {

/// Node classes, in SGPR's id order (its one-hot input rows).
inline constexpr int kNumNodeClasses = 12;
namespace node_class {
inline constexpr int kCar = 0, kTruck = 1, kOtherVehicle = 2, kSidewalk = 3, kOtherGround = 4, kBuilding = 5,
                     kFence = 6, kVegetation = 7, kTrunk = 8, kTerrain = 9, kPole = 10, kTrafficSign = 11;
}

/// Node class of a raw SemanticKITTI id (moving-* first mapped to its static
/// class), or nullopt for classes that give no node: road, parking,
/// lane-marking, unlabeled/outlier/other-*, bicycle, motorcycle, person,
/// bicyclist, motorcyclist.
std::optional<int> node_class_of(std::uint16_t raw_label);
/// "car", "truck", ..., "traffic-sign".
std::string_view node_class_name(int node_class);

/// A node centre coordinate (LiDAR frame, metres) beyond this is not one of a
/// scan: graph readers refuse it, naming the file, and SGPR does not embed it
/// (1e308 would overflow every distance the network computes).
inline constexpr double kMaxGraphCoordinate = 1.0e5;

struct SemanticGraph {
  std::vector<int> nodes;                    ///< node class 0..11 per node
  std::vector<Eigen::Vector3d> centers;      ///< centroid per node, LiDAR frame [m]
  std::vector<std::array<int, 2>> edges;     ///< node index pairs (i < j)
  std::vector<double> weights;               ///< one per edge: 1 - d / edge_distance
  std::optional<std::array<double, 12>> pose;  ///< the scan's 3x4 pose, row-major, when known

  [[nodiscard]] std::size_t size() const { return nodes.size(); }
};

/// The clustering recipe SGPR's weights were trained with.
struct GraphBuilderConfig {
  /// Euclidean clustering tolerance per node class [m]: neighbours closer than this join.
  std::array<double, kNumNodeClasses> tolerance{0.5, 0.5, 0.5, 2.0, 2.0, 2.0, 0.5, 2.0, 0.2, 2.0, 0.2, 0.2};
  /// Smallest Euclidean cluster kept, per node class [points].
  std::array<std::size_t, kNumNodeClasses> min_cluster_size{100, 100, 100, 300, 300, 300, 100, 200, 50, 300, 100, 50};
  /// Larger Euclidean clusters are dropped, as PCL's EuclideanClusterExtraction does.
  std::size_t max_cluster_size = 50000;
  /// Use instance ids where the scan has them. SemanticKITTI annotates
  /// instances only for things, so this applies to car, truck and
  /// other-vehicle points with a non-zero instance id; other points are
  /// clustered geometrically.
  bool use_instances = true;
  /// An instance becomes a cluster when it has more than this many points.
  std::size_t min_instance_points = 20;
  /// At most this many nodes: the largest clusters are kept (see build_semantic_graph).
  std::size_t max_nodes = 100;
  /// Edges join clusters whose nearest points are within this distance [m].
  double edge_distance = 5.0;
};

struct Cluster {
  int node_class = 0;
  std::vector<std::uint32_t> points;  ///< indices into the cloud
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
};

/// PCL-style Euclidean clustering of `points[indices]`: connected components
/// of the graph joining points closer than `tolerance` (inclusive). Uses a
/// voxel hash with cells of tolerance / sqrt(3), so points sharing a cell are
/// joined without any distance test and only neighbouring cells are compared
/// (never quadratic in the cloud size). Components with fewer than
/// `min_size` or more than `max_size` points are dropped. The result is
/// deterministic: clusters ordered by their smallest input position, points
/// in input order.
std::vector<std::vector<std::uint32_t>> euclidean_clusters(std::span<const Eigen::Vector3f> points,
                                                           std::span<const std::uint32_t> indices,
                                                           double tolerance, std::size_t min_size,
                                                           std::size_t max_size);

/// All clusters of a labelled scan (instances and Euclidean clusters), in a
/// deterministic order: by node class, then instance clusters by instance id,
/// then Euclidean clusters in clustering order. Not capped.
std::vector<Cluster> extract_clusters(const LabelledCloud& cloud, const GraphBuilderConfig& config = {});

/// Smallest distance between a point of `a` and a point of `b` (exact; a
/// kd-tree over the larger cluster, queries from points of the smaller one
/// that lie near its bounding box). Returns +inf when it exceeds `max_distance`.
double cluster_distance(const LabelledCloud& cloud, const Cluster& a, const Cluster& b, double max_distance);

/// The semantic graph of one labelled scan. With more than `max_nodes`
/// clusters, the `max_nodes` clusters with the most points are kept (ties:
/// lower node class, then earlier cluster), in their original order; the
/// original SGPR samples at random, which a SLAM system must not.
SemanticGraph build_semantic_graph(const LabelledCloud& cloud, const GraphBuilderConfig& config = {});

}  // namespace saloam
