#include "saloam/place/semantic_scan_context.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <Eigen/Geometry>

#include "saloam/core/semantic_classes.hpp"

namespace saloam {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Codes of the 20 training classes (SemanticKITTI's learning map), in the
// paper's priority order; 0: car, bicycle, motorcycle, truck, other-vehicle,
// person, bicyclist, motorcyclist and unlabelled.
constexpr std::array<std::uint8_t, kNumLearningClasses> kCodeOfLearningClass{
    0, 0, 0, 0, 0, 0, 0, 0, 0,  // unlabeled, car .. motorcyclist
    2,                          // road
    3,                          // parking
    4,                          // sidewalk
    5,                          // other-ground
    7,                          // building
    8,                          // fence
    6,                          // vegetation
    9,                          // trunk
    1,                          // terrain
    10,                         // pole
    11};                        // traffic-sign

/// Sector of an azimuth in [0, 2 pi) (atan2 of y, x shifted by 2 pi when negative).
int sector_of(double x, double y, int sectors) {
  double azimuth = std::atan2(y, x);
  if (azimuth < 0) azimuth += kTwoPi;
  return std::min(static_cast<int>(azimuth * sectors / kTwoPi), sectors - 1);
}

double wrap_angle(double a) {
  a = std::remainder(a, kTwoPi);
  return a <= -std::numbers::pi ? a + kTwoPi : a;
}

/// Radius of the square the stored points cover: the descriptor's outer
/// radius plus the largest accepted alignment (x and y each up to
/// max_translation), so that a moved candidate still fills the descriptor.
double stored_radius(const SscConfig& config) {
  return config.outer_radius + std::numbers::sqrt2 * config.max_translation;
}

/// One point per x-y cell of side cell_size (its highest-priority one; the
/// first read among equals), in cell order.
void thin_points(const LabelledCloud& scan, const SscConfig& config, SemanticScanContext& out) {
  const double radius = stored_radius(config);
  const int side = static_cast<int>(std::ceil(2.0 * radius / config.cell_size));
  std::vector<int> winner(static_cast<std::size_t>(side) * static_cast<std::size_t>(side), -1);
  std::vector<std::uint8_t> winner_code(winner.size(), 0);
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const std::uint8_t code = ssc_class_code(scan.label[i]);
    if (code == 0) continue;
    const double x = scan.points[i].x(), y = scan.points[i].y();
    if (!(x * x + y * y < radius * radius)) continue;
    const int cx = std::clamp(static_cast<int>((x + radius) / config.cell_size), 0, side - 1);
    const int cy = std::clamp(static_cast<int>((y + radius) / config.cell_size), 0, side - 1);
    const std::size_t cell = static_cast<std::size_t>(cy) * static_cast<std::size_t>(side) + static_cast<std::size_t>(cx);
    if (code > winner_code[cell]) {
      winner_code[cell] = code;
      winner[cell] = static_cast<int>(i);
    }
  }
  for (std::size_t cell = 0; cell < winner.size(); ++cell) {
    if (winner[cell] < 0) continue;
    out.points.push_back(scan.points[static_cast<std::size_t>(winner[cell])].head<2>());
    out.codes.push_back(winner_code[cell]);
  }
}

/// The nearest key-class point of each key sector, from all points of the scan.
void find_key_points(const LabelledCloud& scan, const SscConfig& config, SemanticScanContext& out) {
  out.key_range.assign(static_cast<std::size_t>(config.key_sectors), 0.0F);
  out.key_points.assign(static_cast<std::size_t>(config.key_sectors), Eigen::Vector2f::Zero());
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    if (ssc_class_code(scan.label[i]) < kSscFirstKeyCode) continue;
    const Eigen::Vector2f p = scan.points[i].head<2>();
    const float range = p.norm();
    if (!(range > 1e-2F) || !std::isfinite(range)) continue;
    const auto s = static_cast<std::size_t>(sector_of(p.x(), p.y(), config.key_sectors));
    if (out.key_range[s] == 0.0F || range < out.key_range[s]) {
      out.key_range[s] = range;
      out.key_points[s] = p;
    }
  }
}

/// Step 1: the circular shift s minimising sum_j |r_q(j) - r_c(j + s)| (the
/// candidate's sector j + s sees what the query's sector j sees), with a
/// parabola's sub-sector offset; in sectors, [0, n).
double coarse_shift(const std::vector<float>& query, const std::vector<float>& candidate) {
  const int n = static_cast<int>(query.size());
  std::vector<float> doubled(candidate.begin(), candidate.end());
  doubled.insert(doubled.end(), candidate.begin(), candidate.end());
  std::vector<double> cost(static_cast<std::size_t>(n));
  for (int s = 0; s < n; ++s) {
    float sum = 0;
    const float* c = doubled.data() + s;
    for (int j = 0; j < n; ++j) sum += std::abs(query[static_cast<std::size_t>(j)] - c[j]);
    cost[static_cast<std::size_t>(s)] = sum;
  }
  const auto best = static_cast<int>(std::min_element(cost.begin(), cost.end()) - cost.begin());
  const double before = cost[static_cast<std::size_t>((best + n - 1) % n)];
  const double at = cost[static_cast<std::size_t>(best)];
  const double after = cost[static_cast<std::size_t>((best + 1) % n)];
  const double curvature = before - 2.0 * at + after;
  const double offset = curvature > 0 ? std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5) : 0.0;
  return best + offset;
}

struct Correspondences {
  Eigen::Matrix2Xd query, candidate;  ///< matched key points (candidate's moved by the current estimate)
  std::vector<int> pairs;             ///< per query key sector: the matched candidate key sector (-1: none)
  int count = 0;
};

/// The candidate's key points moved by the current estimate, filed by their
/// sector in the query's frame (CSR: `start` has key_sectors + 1 offsets
/// into `members`; a counting sort, so the order is deterministic).
struct MovedKeyPoints {
  std::vector<Eigen::Vector2d> position;
  std::vector<int> start, members;

  void build(const std::vector<Eigen::Vector2d>& points, int sectors) {
    position = points;
    std::vector<int> sector(points.size());
    start.assign(static_cast<std::size_t>(sectors) + 1, 0);
    for (std::size_t k = 0; k < points.size(); ++k) {
      sector[k] = sector_of(points[k].x(), points[k].y(), sectors);
      ++start[static_cast<std::size_t>(sector[k]) + 1];
    }
    for (std::size_t s = 1; s < start.size(); ++s) start[s] += start[s - 1];
    members.assign(points.size(), 0);
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (std::size_t k = 0; k < points.size(); ++k)
      members[static_cast<std::size_t>(fill[static_cast<std::size_t>(sector[k])]++)] = static_cast<int>(k);
  }
};

/// For each query key point, the nearest moved candidate key point whose
/// azimuth (after the move) is within icp_window sectors of the query
/// point's, kept when closer than the gate in x and in y.
Correspondences find_correspondences(const SemanticScanContext& query, const MovedKeyPoints& moved,
                                     const SscConfig& config) {
  const int n = config.key_sectors;
  const int window = std::min(config.icp_window, (n - 1) / 2);  // no sector visited twice
  Correspondences c;
  c.query.resize(2, n);
  c.candidate.resize(2, n);
  c.pairs.assign(static_cast<std::size_t>(n), -1);
  for (int j = 0; j < n; ++j) {
    if (query.key_range[static_cast<std::size_t>(j)] <= 0) continue;
    const Eigen::Vector2d q = query.key_points[static_cast<std::size_t>(j)].cast<double>();
    double best = std::numeric_limits<double>::infinity();
    int best_k = -1;
    int sector = (j - window + n) % n;  // then stepped with a wrap, without a division per sector
    for (int step = 0; step <= 2 * window; ++step, sector = sector + 1 == n ? 0 : sector + 1) {
      const auto s = static_cast<std::size_t>(sector);
      for (int m = moved.start[s]; m < moved.start[s + 1]; ++m) {
        const int k = moved.members[static_cast<std::size_t>(m)];
        const double d = (moved.position[static_cast<std::size_t>(k)] - q).squaredNorm();
        if (d < best) {
          best = d;
          best_k = k;
        }
      }
    }
    if (best_k < 0) continue;
    const Eigen::Vector2d p = moved.position[static_cast<std::size_t>(best_k)];
    if (std::abs(p.x() - q.x()) >= config.icp_gate || std::abs(p.y() - q.y()) >= config.icp_gate) continue;
    c.query.col(c.count) = q;
    c.candidate.col(c.count) = p;
    c.pairs[static_cast<std::size_t>(j)] = best_k;
    ++c.count;
  }
  return c;
}

/// The rigid 2D motion (rotation about the origin, then translation) that
/// best moves the candidate points onto the query points in least squares
/// (closed form); rotation only from 3 correspondences on.
Eigen::Isometry2d fit_rigid_2d(const Correspondences& c) {
  Eigen::Isometry2d step = Eigen::Isometry2d::Identity();
  if (c.count == 0) return step;
  const Eigen::Vector2d mean_q = c.query.leftCols(c.count).rowwise().mean();
  const Eigen::Vector2d mean_c = c.candidate.leftCols(c.count).rowwise().mean();
  double angle = 0;
  if (c.count >= 3) {
    double dot = 0, cross = 0;
    for (int i = 0; i < c.count; ++i) {
      const Eigen::Vector2d a = c.candidate.col(i) - mean_c, b = c.query.col(i) - mean_q;
      dot += a.dot(b);
      cross += a.x() * b.y() - a.y() * b.x();
    }
    angle = std::atan2(cross, dot);
  }
  step.linear() = Eigen::Rotation2Dd(angle).toRotationMatrix();
  step.translation() = mean_q - step.linear() * mean_c;
  return step;
}

/// Step 2: 2D ICP on the key points from the coarse yaw; T_query<-candidate.
/// Ends after icp_iterations, when no pair is left, when the pairs repeat
/// those of the previous iteration (the fit is then already their optimum)
/// or of the one before (nearest neighbours alternating between two sets),
/// or when a step moves less than 1 mm and 0.001 degrees.
SscAlignment refine_alignment(const SemanticScanContext& query, const SemanticScanContext& candidate, double coarse_yaw,
                              const SscConfig& config) {
  std::vector<Eigen::Vector2d> present;  // the candidate's key points, by sector
  for (std::size_t k = 0; k < candidate.key_range.size(); ++k)
    if (candidate.key_range[k] > 0) present.push_back(candidate.key_points[k].cast<double>());
  Eigen::Isometry2d estimate = Eigen::Isometry2d::Identity();
  estimate.linear() = Eigen::Rotation2Dd(coarse_yaw).toRotationMatrix();
  std::vector<Eigen::Vector2d> points(present.size());
  MovedKeyPoints moved;
  std::vector<int> previous_pairs, earlier_pairs;
  SscAlignment result;
  for (int iteration = 0; iteration < config.icp_iterations; ++iteration) {
    for (std::size_t k = 0; k < present.size(); ++k) points[k] = estimate * present[k];
    moved.build(points, config.key_sectors);
    Correspondences c = find_correspondences(query, moved, config);
    result.correspondences = c.count;
    result.iterations = iteration + 1;
    if (c.count == 0 || c.pairs == previous_pairs || c.pairs == earlier_pairs) break;
    const Eigen::Isometry2d step = fit_rigid_2d(c);
    estimate = step * estimate;
    if (step.translation().norm() < 1e-3 && std::abs(Eigen::Rotation2Dd(step.linear()).angle()) < 2e-5) break;
    earlier_pairs = std::move(previous_pairs);
    previous_pairs = std::move(c.pairs);
  }
  result.yaw = wrap_angle(Eigen::Rotation2Dd(estimate.linear()).angle());
  result.translation = estimate.translation();
  return result;
}

}  // namespace

std::uint8_t ssc_class_code(std::uint16_t raw_id) {
  if (is_dynamic(raw_id)) return 0;
  return kCodeOfLearningClass[to_learning_class(raw_id)];
}

std::size_t SemanticScanContext::bytes() const {
  return points.size() * (sizeof(Eigen::Vector2f) + 1) + cells.size() + key_range.size() * sizeof(float) +
         key_points.size() * sizeof(Eigen::Vector2f);
}

SemanticScanContext make_semantic_scan_context(const LabelledCloud& scan, const SscConfig& config) {
  SemanticScanContext d;
  if (scan.has_labels && scan.label.size() == scan.points.size()) {
    thin_points(scan, config, d);
    find_key_points(scan, config, d);
  } else {
    d.key_range.assign(static_cast<std::size_t>(config.key_sectors), 0.0F);
    d.key_points.assign(static_cast<std::size_t>(config.key_sectors), Eigen::Vector2f::Zero());
  }
  d.cells = ssc_cells(d.points, d.codes, SscAlignment{}, config);
  return d;
}

SscAlignment align_semantic_scan_contexts(const SemanticScanContext& query, const SemanticScanContext& candidate,
                                          const SscConfig& config) {
  const auto n = static_cast<std::size_t>(config.key_sectors);
  if (query.key_range.size() != n || candidate.key_range.size() != n)
    throw std::invalid_argument("align_semantic_scan_contexts: descriptors made with another loop.ssc.key_sectors");
  const double shift = coarse_shift(query.key_range, candidate.key_range);
  const double coarse_yaw = wrap_angle(-shift * kTwoPi / config.key_sectors);
  SscAlignment result = refine_alignment(query, candidate, coarse_yaw, config);
  if (std::abs(result.translation.x()) > config.max_translation ||
      std::abs(result.translation.y()) > config.max_translation) {
    result.yaw = coarse_yaw;
    result.translation.setZero();
    result.translation_capped = true;
  }
  return result;
}

std::vector<std::uint8_t> ssc_cells(const std::vector<Eigen::Vector2f>& points, const std::vector<std::uint8_t>& codes,
                                    const SscAlignment& alignment, const SscConfig& config) {
  std::vector<std::uint8_t> cells(static_cast<std::size_t>(config.rings) * static_cast<std::size_t>(config.sectors), 0);
  const Eigen::Matrix2d rotation = Eigen::Rotation2Dd(alignment.yaw).toRotationMatrix();
  const double ring_width = (config.outer_radius - config.inner_radius) / config.rings;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d p = rotation * points[i].cast<double>() + alignment.translation;
    const double range = p.norm();
    if (!(range >= config.inner_radius && range < config.outer_radius)) continue;
    const int ring = std::min(static_cast<int>((range - config.inner_radius) / ring_width), config.rings - 1);
    const int sector = sector_of(p.x(), p.y(), config.sectors);
    std::uint8_t& cell = cells[static_cast<std::size_t>(ring) * static_cast<std::size_t>(config.sectors) +
                               static_cast<std::size_t>(sector)];
    cell = std::max(cell, codes[i]);
  }
  return cells;
}

double ssc_similarity(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  if (a.size() != b.size()) throw std::invalid_argument("ssc_similarity: descriptors of different sizes");
  std::size_t occupied = 0, equal = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] == 0 && b[i] == 0) continue;
    ++occupied;
    equal += a[i] == b[i];
  }
  return occupied > 0 ? static_cast<double>(equal) / static_cast<double>(occupied) : 0.0;
}

SscMatch match_semantic_scan_contexts(const SemanticScanContext& query, const SemanticScanContext& candidate,
                                      const SscConfig& config) {
  SscMatch match;
  match.alignment = align_semantic_scan_contexts(query, candidate, config);
  match.score = ssc_similarity(query.cells, ssc_cells(candidate.points, candidate.codes, match.alignment, config));
  return match;
}

}  // namespace saloam
