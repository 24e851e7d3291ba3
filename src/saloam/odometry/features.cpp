#include "saloam/odometry/features.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <utility>


#include "saloam/core/semantic_classes.hpp"
#include "saloam/core/parallel.hpp"
#include "saloam/scan/rings.hpp"
#include "saloam/odometry/gravity.hpp"

namespace saloam {

std::vector<double> ring_roughness(const std::vector<Eigen::Vector3d>& ring, int half_window) {
  const int n = static_cast<int>(ring.size());
  std::vector<double> c(ring.size(), std::numeric_limits<double>::infinity());
  if (n < 2 * half_window + 1) return c;
  // Running sum over the window: sum_{j in S} X_j = window_sum - X_i.
  Eigen::Vector3d window = Eigen::Vector3d::Zero();
  for (int j = 0; j < 2 * half_window + 1; ++j) window += ring[j];
  for (int i = half_window; i < n - half_window; ++i) {
    if (i > half_window) window += ring[i + half_window] - ring[i - half_window - 1];
    const Eigen::Vector3d diff = window - static_cast<double>(2 * half_window + 1) * ring[i];
    c[i] = diff.squaredNorm();
  }
  return c;
}

namespace {
/// sqrt(squared) > limit (limit > 0), without the square root when the
/// squared value is clearly below limit^2 (the usual case): the result is
/// the same as comparing the rounded square root.
bool exceeds(double squared, double limit) {
  if (squared < 0.99 * limit * limit) return false;
  return std::sqrt(squared) > limit;
}
}  // namespace

namespace {
/// Squared distances between ring neighbours: gap_sq[i] = |X_{i+1} - X_i|^2
/// (the last is 0). The tests for unreliable points and the suppression of
/// selected points' neighbours both read them.
std::vector<double> squared_gaps(const std::vector<Eigen::Vector3d>& ring) {
  std::vector<double> gap_sq(ring.size(), 0.0);
  for (std::size_t i = 0; i + 1 < ring.size(); ++i) gap_sq[i] = (ring[i + 1] - ring[i]).squaredNorm();
  return gap_sq;
}

PointMask unreliable_points(const std::vector<Eigen::Vector3d>& ring, const std::vector<double>& gap_sq,
                            int half_window, double min_range, double max_range) {
  const int n = static_cast<int>(ring.size());
  PointMask bad(ring.size(), 0);
  std::vector<double> range(ring.size());
  for (int i = 0; i < n; ++i) {
    range[i] = ring[i].norm();
    if (range[i] < min_range || range[i] > max_range) bad[i] = 1;
  }
  for (int i = 0; i + 1 < n; ++i) {
    // Neighbouring returns far apart relative to their range: either a depth
    // jump (occlusion) or a hole in azimuth. Angular step of the HDL-64E is
    // ~0.17 deg (3e-3 rad); 0.3 m at 10 m is ~10 steps.
    if (exceeds(gap_sq[i], 0.03 * std::max(range[i], 1.0) + 0.1)) {
      const double near = std::min(range[i], range[i + 1]);
      const bool depth_jump = std::abs(range[i] - range[i + 1]) > 0.1 * near + 0.1;
      if (depth_jump) {
        // Occluded side: the farther points next to the jump lie on a surface
        // that continues behind the nearer object; their "edge" is an artefact.
        if (range[i] > range[i + 1]) {
          for (int k = std::max(0, i - half_window + 1); k <= i; ++k) bad[k] = 1;
        } else {
          for (int k = i + 1; k <= std::min(n - 1, i + half_window); ++k) bad[k] = 1;
        }
      } else {
        // A hole in azimuth (no return): windows across it are not local.
        for (int k = std::max(0, i - half_window + 1); k <= std::min(n - 1, i + half_window); ++k) {
          bad[k] = 1;
        }
      }
    }
  }
  // Beams nearly parallel to the surface: both neighbour gaps large relative
  // to the range (LOAM's 0.0002 * range^2 on the squared gap).
  for (int i = 1; i + 1 < n; ++i) {
    const double limit = 0.0002 * range[i] * range[i];
    if (gap_sq[i - 1] > limit && gap_sq[i] > limit) bad[i] = 1;
  }
  return bad;
}
}  // namespace

PointMask unreliable_points(const std::vector<Eigen::Vector3d>& ring, int half_window, double min_range,
                            double max_range) {
  return unreliable_points(ring, squared_gaps(ring), half_window, min_range, max_range);
}

namespace {
/// Sorts keys (32-bit sort value above a 32-bit index) that were pushed in
/// increasing index order: a stable radix sort on the upper half, one pass per
/// byte that is not the same in every key, keeps equal values in index order
/// and so gives the same order as a comparison sort of the whole keys, in
/// linear time (a sector's few hundred keys sort several times faster).
void sort_keys_pushed_in_index_order(std::vector<std::uint64_t>& keys, std::vector<std::uint64_t>& scratch) {
  if (keys.size() < 2) return;
  constexpr int kFirstByte = 4, kBytes = 8;
  std::array<std::array<std::uint32_t, 256>, kBytes - kFirstByte> counts{};
  for (const std::uint64_t k : keys) {
    for (int b = kFirstByte; b < kBytes; ++b) ++counts[b - kFirstByte][(k >> (8 * b)) & 0xff];
  }
  scratch.resize(keys.size());
  for (int b = kFirstByte; b < kBytes; ++b) {
    auto& count = counts[b - kFirstByte];
    if (count[(keys.front() >> (8 * b)) & 0xff] == keys.size()) continue;  // one bucket: nothing moves
    std::uint32_t offset = 0;
    for (auto& c : count) offset += std::exchange(c, offset);
    for (const std::uint64_t k : keys) scratch[count[(k >> (8 * b)) & 0xff]++] = k;
    keys.swap(scratch);
  }
}
}  // namespace

namespace {
/// A point's sort key: its roughness as float bits (order-preserving for
/// non-negative values) above its index: ascending keys order by roughness,
/// ties by position, and the ring's features are the same as with a
/// comparison sort on (roughness, index).
std::uint64_t roughness_key(double c, int i) {
  std::uint32_t bits = 0;
  const float f = static_cast<float>(c);
  std::memcpy(&bits, &f, sizeof bits);
  return (static_cast<std::uint64_t>(bits) << 32) | static_cast<std::uint32_t>(i);
}
int key_index(std::uint64_t k) { return static_cast<int>(k & 0xffffffffu); }
std::uint64_t key_roughness_bits(std::uint64_t k) { return k >> 32; }

/// Picks one ring's features sector by sector. One sort of a sector's usable
/// points serves both kinds: edges are taken from its rough end down, planar
/// points from its smooth end up, and each pick blocks its ring neighbours.
/// Rounding to float keeps the order, so only keys whose float equals
/// alpha's can be on either side, and the loops test each key's roughness.
class RingFeaturePicker {
 public:
  RingFeaturePicker(const std::vector<double>& gap_sq, const std::vector<double>& roughness,
                    const PointMask& unreliable, const FeatureConfig& config, const PointMask& not_edge)
      : gap_sq_(gap_sq), roughness_(roughness), not_edge_(not_edge), config_(config), blocked_(unreliable),
        alpha_bits_(key_roughness_bits(roughness_key(config.alpha, 0))) {}

  /// The features among ring points [begin, end).
  void pick_sector(int begin, int end, RingSelection& out) {
    sort_usable(begin, end);
    pick_edges(out.edges);
    pick_planars(out.planars);
  }

 private:
  void sort_usable(int begin, int end) {
    keys_.resize(static_cast<std::size_t>(end - begin));
    std::size_t count = 0;
    for (int i = begin; i < end; ++i) {
      const double c = roughness_[i];
      keys_[count] = roughness_key(c, i);
      count += !blocked_[i] && std::isfinite(c) && c != config_.alpha;  // no branch: roughness is unpredictable
    }
    keys_.resize(count);
    sort_keys_pushed_in_index_order(keys_, scratch_);
  }

  void pick_edges(std::vector<int>& edges) {
    int picked = 0;
    for (auto it = keys_.rbegin(); it != keys_.rend() && picked < config_.edges_per_sector; ++it) {
      if (key_roughness_bits(*it) < alpha_bits_) break;  // all smoother than alpha from here
      const int i = key_index(*it);
      if (!(roughness_[i] > config_.alpha) || blocked_[i] || (!not_edge_.empty() && not_edge_[i])) continue;
      edges.push_back(i);
      block_neighbours(i);
      ++picked;
    }
  }

  void pick_planars(std::vector<int>& planars) {
    int picked = 0;
    for (auto it = keys_.begin(); it != keys_.end() && picked < config_.planars_per_sector; ++it) {
      if (key_roughness_bits(*it) > alpha_bits_) break;  // all rougher than alpha from here
      const int i = key_index(*it);
      if (!(roughness_[i] < config_.alpha) || blocked_[i]) continue;
      planars.push_back(i);
      block_neighbours(i);
      ++picked;
    }
  }

  /// Blocks the ring neighbours of a selected point, as long as they are
  /// close in space (not across an occlusion).
  void block_neighbours(int i) {
    const int n = static_cast<int>(gap_sq_.size());
    blocked_[i] = 1;
    for (int step : {-1, 1}) {
      for (int k = 1; k <= config_.roughness_half_window; ++k) {
        const int j = i + step * k;
        const int prev = j - step;
        if (j < 0 || j >= n) break;
        if (gap_sq_[std::min(j, prev)] > 0.05) break;
        blocked_[j] = 1;
      }
    }
  }

  const std::vector<double>& gap_sq_;
  const std::vector<double>& roughness_;
  const PointMask& not_edge_;
  const FeatureConfig& config_;
  PointMask blocked_;
  std::uint64_t alpha_bits_;
  std::vector<std::uint64_t> keys_, scratch_;
};

RingSelection select_ring_features(const std::vector<double>& gap_sq, const std::vector<double>& roughness,
                                   const PointMask& unreliable, const FeatureConfig& config,
                                   const PointMask& not_edge) {
  RingSelection out;
  const int n = static_cast<int>(gap_sq.size());
  const int w = config.roughness_half_window;
  if (n < 2 * w + 1) return out;
  const int first = w, last = n - w;  // points with a full window
  const int sectors = std::max(1, config.num_sectors);
  RingFeaturePicker picker(gap_sq, roughness, unreliable, config, not_edge);
  for (int s = 0; s < sectors; ++s) {
    const int begin = first + (last - first) * s / sectors;
    const int end = first + (last - first) * (s + 1) / sectors;
    if (end > begin) picker.pick_sector(begin, end, out);
  }
  return out;
}
}  // namespace

RingSelection select_ring_features(const std::vector<Eigen::Vector3d>& ring,
                                   const std::vector<double>& roughness,
                                   const PointMask& unreliable, const FeatureConfig& config,
                                   const PointMask& not_edge) {
  return select_ring_features(squared_gaps(ring), roughness, unreliable, config, not_edge);
}

bool is_thin_round(std::uint16_t static_class_id) {
  return static_class_id == cls::kPole || static_class_id == cls::kTrunk;
}

namespace {
/// Horizontal angle between two points seen from the sensor [rad].
double azimuth_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::abs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.x() * b.x() + a.y() * b.y()));
}

/// Mean of sqrt(r^2 - x^2) over x in [s - h, s + h] within [-r, r]: how far
/// in front of a disc's centre a ray at lateral offset s (known to +-h) meets it.
double mean_chord_depth(double r, double s, double h) {
  const double a = std::max(s - h, -r), b = std::min(s + h, r);
  if (b - a <= 1e-9 * r) return std::sqrt(std::max(0.0, r * r - s * s));
  const auto antiderivative = [r](double x) {
    return 0.5 * (x * std::sqrt(std::max(0.0, r * r - x * x)) + r * r * std::asin(std::clamp(x / r, -1.0, 1.0)));
  };
  return (antiderivative(b) - antiderivative(a)) / (b - a);
}

/// The mean distance from the sensor to the axis of a disc of radius r on
/// the horizontal ray `axis_ray`, estimated by each return of [first, last].
double axis_distance(const std::vector<Eigen::Vector3d>& ring, int first, int last, const Eigen::Vector2d& axis_ray,
                     double radius, double half_step_width) {
  const Eigen::Vector2d across(-axis_ray.y(), axis_ray.x());
  double sum = 0.0;
  for (int j = first; j <= last; ++j) {
    const Eigen::Vector2d p = ring[j].head<2>();
    sum += p.dot(axis_ray) + mean_chord_depth(radius, p.dot(across), half_step_width);
  }
  return sum / (last - first + 1);
}

double horizontal_range(const Eigen::Vector3d& p) { return p.head<2>().norm(); }

/// Ring neighbours farther apart in azimuth than this many steps have no
/// return between them.
constexpr double kMaxStepsBetweenReturns = 2.5;

/// The returns of one object crossing, ring indices [first, last], and the
/// azimuth step between returns.
struct Crossing {
  int first = 0, last = 0;
  double step = 0.0;
};

/// The crossing around ring index k: the neighbours whose horizontal ranges
/// change by less than `max_radius` from one to the next (the near side of
/// a disc of that radius, its silhouette's grazing returns included), or
/// nothing when something nearer cuts it at either end.
std::optional<Crossing> crossing_at(const std::vector<Eigen::Vector3d>& ring, int k, double max_radius) {
  const int n = static_cast<int>(ring.size());
  // The step: the smaller azimuth gap to a neighbour (the other may be a hole).
  const double step = std::min(k > 0 ? azimuth_between(ring[k - 1], ring[k]) : M_PI,
                               k + 1 < n ? azimuth_between(ring[k], ring[k + 1]) : M_PI);
  if (!(step > 0.0) || step >= M_PI) return std::nullopt;
  const auto adjacent = [&](int a, int b) { return azimuth_between(ring[a], ring[b]) <= kMaxStepsBetweenReturns * step; };
  const auto same_object = [&](int a, int b) {
    return adjacent(a, b) && std::abs(horizontal_range(ring[a]) - horizontal_range(ring[b])) < max_radius;
  };
  Crossing c{k, k, step};
  while (c.first > 0 && same_object(c.first - 1, c.first)) --c.first;
  while (c.last + 1 < n && same_object(c.last, c.last + 1)) ++c.last;
  // Beyond each end: no return, or a farther surface; a nearer one hides part of the object.
  const auto cut = [&](int end, int beyond) {
    if (beyond < 0 || beyond >= n) return true;
    return adjacent(end, beyond) && horizontal_range(ring[beyond]) < horizontal_range(ring[end]);
  };
  if (cut(c.first, c.first - 1) || cut(c.last, c.last + 1)) return std::nullopt;
  if (c.last > c.first) c.step = azimuth_between(ring[c.first], ring[c.last]) / (c.last - c.first);
  return c;
}
}  // namespace

std::optional<ThinObjectAxis> thin_object_axis(const std::vector<Eigen::Vector3d>& ring, int k, double max_radius) {
  if (k < 0 || k >= static_cast<int>(ring.size()) || ring.size() < 2) return std::nullopt;
  const auto crossing = crossing_at(ring, k, max_radius);
  if (!crossing) return std::nullopt;
  const auto [first, last, step] = *crossing;
  const int count = last - first + 1;
  const Eigen::Vector2d towards = ring[first].head<2>().normalized() + ring[last].head<2>().normalized();
  if (!(towards.squaredNorm() > 0.0)) return std::nullopt;
  const Eigen::Vector2d axis_ray = towards.normalized();
  double distance = 0.0, mean_z = 0.0;
  for (int j = first; j <= last; ++j) {
    distance += horizontal_range(ring[j]);
    mean_z += ring[j].z();
  }
  distance /= count;
  mean_z /= count;
  // The run's angular width is the chord's as seen at the axis's distance:
  // the radius and that distance are refined once from each other.
  double radius = 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    const double half_step_width = 0.5 * step * distance;
    radius = count * half_step_width;
    if (!(radius <= max_radius)) return std::nullopt;
    distance = axis_distance(ring, first, last, axis_ray, radius, half_step_width);
  }
  ThinObjectAxis axis;
  axis.point << distance * axis_ray, mean_z;
  axis.central = (first + last) / 2;
  axis.radius = radius;
  return axis;
}

namespace {
int compute_odometry_class(std::uint16_t raw_label) {
  if (raw_label == cls::kUnlabeled || raw_label == cls::kOutlier || is_dynamic(raw_label)) return -1;
  const int learning = to_learning_class(static_class(raw_label));
  return learning == 0 ? -1 : learning;
}
}  // namespace

ClassIndex class_group(ClassIndex c) {
  static const std::array<ClassIndex, kNumClassIndices> table = [] {
    std::array<ClassIndex, kNumClassIndices> t{};
    for (int i = 0; i < kNumClassIndices; ++i) t[i] = static_cast<ClassIndex>(i);
    auto group = [&](std::initializer_list<std::uint16_t> members, std::uint16_t representative) {
      for (const auto m : members) t[to_learning_class(m)] = to_learning_class(representative);
    };
    group({cls::kRoad, cls::kParking, cls::kSidewalk, cls::kOtherGround, cls::kTerrain}, cls::kRoad);
    group({cls::kBuilding, cls::kFence}, cls::kBuilding);
    group({cls::kPole, cls::kTrunk, cls::kTrafficSign}, cls::kPole);
    group({cls::kCar, cls::kBicycle, cls::kMotorcycle, cls::kTruck, cls::kOtherVehicle}, cls::kCar);
    return t;
  }();
  return c < table.size() ? table[c] : c;
}

namespace {
/// odometry_class of the raw labels below 512 (raw ids are below 260): a
/// table avoids the class-table search per point.
using OdometryClassTable = std::array<std::int8_t, 512>;
const OdometryClassTable& odometry_class_table() {
  static const OdometryClassTable table = [] {
    OdometryClassTable t{};
    for (std::size_t id = 0; id < t.size(); ++id) t[id] = static_cast<std::int8_t>(compute_odometry_class(static_cast<std::uint16_t>(id)));
    return t;
  }();
  return table;
}
int odometry_class(const OdometryClassTable& table, std::uint16_t raw_label) {
  return raw_label < table.size() ? table[raw_label] : compute_odometry_class(raw_label);
}
}  // namespace

int odometry_class(std::uint16_t raw_label) { return odometry_class(odometry_class_table(), raw_label); }

namespace {
/// [m] the lowest ring's returns horizontally nearer than this measure the ground.
constexpr double kGroundEstimateRange = 20.0;
/// Fewer of them measure nothing.
constexpr std::size_t kMinGroundReturns = 20;

/// The ground's height below the sensor [m], along up (`level` turns the
/// sensor frame level: level * p has z up): the median height of the lowest
/// ring's returns within kGroundEstimateRange (that ring looks down most
/// steeply, so near the car it mostly hits the road), or nothing when too
/// few are there.
std::optional<double> ground_height(const LabelledCloud& cloud, const std::vector<std::vector<std::uint32_t>>& rings,
                                    const Eigen::Matrix3f& level) {
  const std::vector<std::uint32_t>* lowest = nullptr;
  double lowest_slope = kInf;
  for (const auto& ring : rings) {
    if (ring.size() < kMinGroundReturns) continue;
    double slope = 0.0;  // mean height / horizontal range, over a sample of the ring
    std::size_t n = 0;
    for (std::size_t k = 0; k < ring.size(); k += 8, ++n) {
      const Eigen::Vector3f p = level * cloud.points[ring[k]];
      slope += p.z() / std::max(1e-3f, p.head<2>().norm());
    }
    slope /= static_cast<double>(n);
    if (slope < lowest_slope) {
      lowest_slope = slope;
      lowest = &ring;
    }
  }
  if (lowest == nullptr) return std::nullopt;
  std::vector<double> heights;
  for (const auto i : *lowest) {
    const Eigen::Vector3f p = level * cloud.points[i];
    if (p.head<2>().norm() < kGroundEstimateRange) heights.push_back(p.z());
  }
  if (heights.size() < kMinGroundReturns) return std::nullopt;
  const auto middle = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2);
  std::nth_element(heights.begin(), middle, heights.end());
  return *middle;
}
}  // namespace

namespace {
/// What every ring's feature extraction reads besides the ring itself.
struct RingInputs {
  const LabelledCloud& cloud;
  const std::vector<float>& sweep_times;  ///< [s] per point, for de-skewing
  const FeatureConfig& config;
  const OdometryClassTable& class_table;
  bool use_labels;
  std::optional<double> no_edges_below;  ///< [m] height along up, without labels
  /// The sensor frame turned level (level * p has z up), when up is not the
  /// sensor's z: heights and a thin object's axis are taken along up.
  std::optional<Eigen::Matrix3d> level;
};

/// With labels: points of classes odometry does not use are made unreliable
/// (they must not take a sector's feature slots), and ground points rough
/// enough for an edge but not for ground_edge_alpha are marked no edge.
PointMask apply_labels(const RingInputs& in, const std::vector<std::uint32_t>& ring,
                       const std::vector<double>& roughness, PointMask& unreliable) {
  const FeatureConfig& config = in.config;
  const bool ground_threshold = config.ground_edge_alpha > config.alpha;
  PointMask not_edge;
  if (ground_threshold) not_edge.assign(ring.size(), 0);
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const std::uint16_t label = in.cloud.label[ring[k]];
    unreliable[k] |= odometry_class(in.class_table, label) < 0;
    // Only points rough enough to be edges at all need the class lookup.
    if (ground_threshold && roughness[k] > config.alpha && !(roughness[k] > config.ground_edge_alpha) &&
        is_ground(static_class(label))) {
      not_edge[k] = 1;
    }
  }
  return not_edge;
}

/// The selected ring points `indices` into `target` with class and sweep
/// time; an edge of a thin round object stands for its axis (ThinObjectAxis).
void emit_features(const RingInputs& in, const std::vector<std::uint32_t>& ring,
                   const std::vector<Eigen::Vector3d>& ring_points, const std::vector<Eigen::Vector3d>& level_points,
                   const std::vector<int>& indices, bool edges, FeatureCloud& target) {
  const bool axes = in.use_labels && in.config.thin_object_axes;
  for (const int k : indices) {
    const std::uint32_t i = ring[k];
    int c = 0;
    if (in.use_labels) {
      c = odometry_class(in.class_table, in.cloud.label[i]);
      if (c < 0) continue;
    }
    if (edges && axes && is_thin_round(static_class(in.cloud.label[i]))) {
      // Poles and trunks stand upright: the axis is found in the level frame.
      const auto axis = thin_object_axis(level_points, k, in.config.thin_object_max_radius);
      if (!axis) continue;
      const std::uint32_t central = ring[static_cast<std::size_t>(axis->central)];
      const Eigen::Vector3d point = in.level ? Eigen::Vector3d(in.level->transpose() * axis->point) : axis->point;
      target.push_back(point, static_cast<ClassIndex>(c), in.sweep_times[central]);
      continue;
    }
    target.push_back(ring_points[k], static_cast<ClassIndex>(c), in.sweep_times[i]);
  }
}

/// One ring's features (`ring`: point indices in azimuth order).
ScanFeatures ring_features(const RingInputs& in, const std::vector<std::uint32_t>& ring) {
  const FeatureConfig& config = in.config;
  std::vector<Eigen::Vector3d> ring_points(ring.size());
  for (std::size_t k = 0; k < ring.size(); ++k) ring_points[k] = in.cloud.points[ring[k]].cast<double>();
  const auto roughness = ring_roughness(ring_points, config.roughness_half_window);
  const auto gap_sq = squared_gaps(ring_points);
  auto unreliable =
      unreliable_points(ring_points, gap_sq, config.roughness_half_window, config.min_range, config.max_range);
  // The ring turned level where up is not the sensor's z (heights, axes).
  std::vector<Eigen::Vector3d> turned;
  if (in.level) {
    turned.resize(ring_points.size());
    for (std::size_t k = 0; k < ring_points.size(); ++k) turned[k] = *in.level * ring_points[k];
  }
  const std::vector<Eigen::Vector3d>& level_points = in.level ? turned : ring_points;
  PointMask not_edge;
  if (in.use_labels) not_edge = apply_labels(in, ring, roughness, unreliable);
  if (in.no_edges_below) {
    not_edge.assign(ring.size(), 0);
    for (std::size_t k = 0; k < ring.size(); ++k) not_edge[k] = level_points[k].z() < *in.no_edges_below;
  }
  const auto selection = select_ring_features(gap_sq, roughness, unreliable, config, not_edge);
  ScanFeatures out;
  emit_features(in, ring, ring_points, level_points, selection.edges, true, out.edges);
  emit_features(in, ring, ring_points, level_points, selection.planars, false, out.planars);
  return out;
}

void append(FeatureCloud& to, const FeatureCloud& from) {
  to.points.insert(to.points.end(), from.points.begin(), from.points.end());
  to.classes.insert(to.classes.end(), from.classes.begin(), from.classes.end());
  to.sweep_time.insert(to.sweep_time.end(), from.sweep_time.begin(), from.sweep_time.end());
}
}  // namespace

ScanFeatures extract_features(const LabelledCloud& cloud, const FeatureConfig& config, bool use_labels,
                              bool parallel, const Eigen::Vector3d& up) {
  // Rings (point indices in azimuth order) from the point order when the scan
  // is stored ring by ring (exact even for scans whose points were moved by
  // motion compensation), else from the elevation angle.
  const std::vector<float> times = point_sweep_times(cloud, config, parallel);
  const std::vector<std::vector<std::uint32_t>> rings = rings_from_times(cloud, times, config);
  // De-skewing takes the points' own times when the scan has them
  // (relative to the scan's timestamp), else the sweep model's.
  RingInputs inputs{cloud, cloud.has_times() ? cloud.time : times, config, odometry_class_table(), use_labels, {}, {}};
  // Heights are along up (odometry/gravity.hpp): the sensor's z only when it points up.
  const Eigen::Vector3d unit_up = up.normalized();
  if (!points_up(unit_up)) inputs.level = level_rotation(unit_up);
  // Without labels, the ground is what lies near the lowest ring's height.
  if (!use_labels && config.unlabelled_ground_margin > 0.0) {
    const Eigen::Matrix3f level = inputs.level ? Eigen::Matrix3f(inputs.level->cast<float>()) : Eigen::Matrix3f::Identity();
    if (const auto ground = ground_height(cloud, rings, level)) {
      inputs.no_edges_below = *ground + config.unlabelled_ground_margin;
    }
  }
  // Rings are independent: with `parallel`, one task per ring; the results
  // are concatenated in ring order so the output does not depend on threads.
  std::vector<ScanFeatures> per_ring(rings.size());
  for_each_index(rings.size(), parallel, 1, [&](std::size_t r) { per_ring[r] = ring_features(inputs, rings[r]); });
  ScanFeatures out;
  for (const auto& f : per_ring) {
    append(out.edges, f.edges);
    append(out.planars, f.planars);
  }
  return out;
}

FeatureCloud transformed(const FeatureCloud& cloud, const Pose& T) {
  FeatureCloud out = cloud;
  for (auto& p : out.points) p = T * p;
  return out;
}

}  // namespace saloam
