#include "saloam/eval/trajectory_metrics.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <fmt/format.h>

namespace saloam {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using Matrix4 = Eigen::Matrix4d;

/// inv(A) * B with a general inverse (the devkit's Matrix::inv), see header.
Matrix4 relative(const Pose& a, const Pose& b) { return a.matrix().inverse() * b.matrix(); }

/// Rotation angle of the top-left 3x3 block, clamped acos as in the devkit.
double angle_of(const Matrix4& m) {
  const double c = 0.5 * (m(0, 0) + m(1, 1) + m(2, 2) - 1.0);
  return std::acos(std::clamp(c, -1.0, 1.0));
}

void require_same_size(const std::vector<Pose>& gt, const std::vector<Pose>& est, const char* what) {
  if (gt.size() != est.size()) {
    throw std::invalid_argument(
        fmt::format("{}: ground truth has {} poses but the estimate {}", what, gt.size(), est.size()));
  }
}

}  // namespace

// ---------------------------------------------------------------------------
// KITTI
// ---------------------------------------------------------------------------

std::vector<double> trajectory_distances(const std::vector<Pose>& poses) {
  std::vector<double> dist;
  dist.reserve(poses.size());
  if (poses.empty()) return dist;
  dist.push_back(0.0);
  for (std::size_t i = 1; i < poses.size(); ++i) {
    dist.push_back(dist.back() + (poses[i].translation() - poses[i - 1].translation()).norm());
  }
  return dist;
}

KittiMetrics compute_kitti_metrics(const std::vector<Pose>& gt, const std::vector<Pose>& est,
                                   const KittiOptions& options) {
  require_same_size(gt, est, "KITTI metrics");
  if (options.step_frames == 0) throw std::invalid_argument("KITTI metrics: step_frames must be positive");

  KittiMetrics result;
  const std::vector<double> dist = trajectory_distances(gt);
  std::vector<double> t_sum(options.lengths_m.size(), 0.0), r_sum(options.lengths_m.size(), 0.0);
  std::vector<std::size_t> count(options.lengths_m.size(), 0);

  for (std::size_t first = 0; first < gt.size(); first += options.step_frames) {
    for (std::size_t k = 0; k < options.lengths_m.size(); ++k) {
      const double len = options.lengths_m[k];
      // The devkit scans forward for the first frame with dist > dist[first] + len;
      // dist is non-decreasing, so upper_bound finds the same frame.
      const auto it = std::upper_bound(dist.begin() + static_cast<std::ptrdiff_t>(first), dist.end(), dist[first] + len);
      if (it == dist.end()) continue;
      const auto last = static_cast<std::size_t>(it - dist.begin());

      const Matrix4 delta_gt = relative(gt[first], gt[last]);
      const Matrix4 delta_est = relative(est[first], est[last]);
      const Matrix4 error = delta_est.inverse() * delta_gt;  // devkit: inv(delta_result) * delta_gt

      KittiSegmentError seg;
      seg.first_frame = first;
      seg.last_frame = last;
      seg.length_m = len;
      seg.t_err = error.block<3, 1>(0, 3).norm() / len;
      seg.r_err = angle_of(error) / len;
      t_sum[k] += seg.t_err;
      r_sum[k] += seg.r_err;
      ++count[k];
      result.segment_errors.push_back(seg);
    }
  }

  // The sequence value averages all segments (not the per-length means).
  double t_total = 0.0, r_total = 0.0;
  for (const auto& seg : result.segment_errors) {
    t_total += seg.t_err;
    r_total += seg.r_err;
  }
  result.segments = result.segment_errors.size();
  const double n = static_cast<double>(result.segments);
  result.t_err_percent = result.segments ? 100.0 * t_total / n : kNaN;
  result.r_err_deg_per_100m = result.segments ? 100.0 * kRadToDeg * r_total / n : kNaN;

  for (std::size_t k = 0; k < options.lengths_m.size(); ++k) {
    KittiLengthError e;
    e.length_m = options.lengths_m[k];
    e.segments = count[k];
    const double c = static_cast<double>(count[k]);
    e.t_err_percent = count[k] ? 100.0 * t_sum[k] / c : kNaN;
    e.r_err_deg_per_100m = count[k] ? 100.0 * kRadToDeg * r_sum[k] / c : kNaN;
    result.per_length.push_back(e);
  }
  return result;
}

// ---------------------------------------------------------------------------
// Alignment and ATE
// ---------------------------------------------------------------------------

Alignment parse_alignment(const std::string& name) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  if (lower == "none") return Alignment::kNone;
  if (lower == "se3") return Alignment::kSE3;
  if (lower == "sim3") return Alignment::kSim3;
  throw std::invalid_argument(fmt::format("unknown alignment '{}' (use se3, sim3 or none)", name));
}

std::string alignment_name(Alignment alignment) {
  switch (alignment) {
    case Alignment::kNone: return "none";
    case Alignment::kSE3: return "se3";
    case Alignment::kSim3: return "sim3";
  }
  return "unknown";
}

Pose SimilarityTransform::apply(const Pose& pose) const {
  Pose out = Pose::Identity();
  out.linear() = rotation * pose.linear();
  out.translation() = apply(Eigen::Vector3d(pose.translation()));
  return out;
}

SimilarityTransform umeyama_alignment(const std::vector<Eigen::Vector3d>& source,
                                      const std::vector<Eigen::Vector3d>& target, bool with_scale) {
  if (source.empty() || source.size() != target.size()) {
    throw std::invalid_argument(
        fmt::format("umeyama_alignment: need equal, non-zero point counts (got {} and {})", source.size(), target.size()));
  }
  const double n = static_cast<double>(source.size());
  Eigen::Vector3d mu_source = Eigen::Vector3d::Zero(), mu_target = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i) {
    mu_source += source[i];
    mu_target += target[i];
  }
  mu_source /= n;
  mu_target /= n;

  // Cross-covariance Sigma_xy (eq. 38) and source variance sigma_x^2 (eq. 36).
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
  double var_source = 0.0;
  for (std::size_t i = 0; i < source.size(); ++i) {
    const Eigen::Vector3d ds = source[i] - mu_source;
    sigma += (target[i] - mu_target) * ds.transpose();
    var_source += ds.squaredNorm();
  }
  sigma /= n;
  var_source /= n;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  // Reflection guard (eq. 39): force det(R) = +1.
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;

  SimilarityTransform T;
  T.rotation = svd.matrixU() * S * svd.matrixV().transpose();                               // eq. 40
  T.scale = with_scale && var_source > 0.0 ? (svd.singularValues().asDiagonal() * S).trace() / var_source : 1.0;  // eq. 42
  T.translation = mu_target - T.scale * T.rotation * mu_source;                              // eq. 41
  return T;
}

ErrorStats error_stats(const std::vector<double>& errors) {
  ErrorStats s;
  s.count = errors.size();
  if (errors.empty()) {
    s.rmse = s.mean = s.median = s.max = s.min = kNaN;
    return s;
  }
  double sum = 0.0, sum_sq = 0.0;
  for (double e : errors) {
    sum += e;
    sum_sq += e * e;
  }
  const double n = static_cast<double>(errors.size());
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  const std::size_t mid = sorted.size() / 2;
  s.median = sorted.size() % 2 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
  s.min = sorted.front();
  s.max = sorted.back();
  return s;
}

std::vector<std::pair<std::size_t, std::size_t>> associate_by_time(const std::vector<double>& gt,
                                                                   const std::vector<double>& est,
                                                                   double max_difference) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  std::size_t next_gt = 0;  // gt times before this are used or passed
  for (std::size_t e = 0; e < est.size(); ++e) {
    const auto at = std::lower_bound(gt.begin() + static_cast<std::ptrdiff_t>(next_gt), gt.end(), est[e]);
    std::size_t best = gt.size();
    double best_gap = max_difference;
    for (auto it : {at - (at != gt.begin() + static_cast<std::ptrdiff_t>(next_gt) ? 1 : 0), at}) {
      if (it == gt.end()) continue;
      const double gap = std::abs(*it - est[e]);
      if (gap <= best_gap) {
        best_gap = gap;
        best = static_cast<std::size_t>(it - gt.begin());
      }
    }
    if (best == gt.size()) continue;
    pairs.emplace_back(best, e);
    next_gt = best + 1;
  }
  return pairs;
}

AteMetrics compute_ate(const std::vector<Pose>& gt, const std::vector<Pose>& est, Alignment alignment) {
  require_same_size(gt, est, "ATE");
  if (gt.empty()) throw std::invalid_argument("ATE: empty trajectories");
  std::vector<Eigen::Vector3d> p_gt, p_est;
  p_gt.reserve(gt.size());
  p_est.reserve(est.size());
  for (std::size_t i = 0; i < gt.size(); ++i) {
    p_gt.emplace_back(gt[i].translation());
    p_est.emplace_back(est[i].translation());
  }

  AteMetrics m;
  m.alignment = alignment;
  if (alignment == Alignment::kSim3) {
    // A trajectory that does not move has no scale: Umeyama's would be 0 (or
    // undefined) and shrink the other onto one point, an ATE of 0.
    const auto spread = [](const std::vector<Eigen::Vector3d>& p) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const auto& x : p) mean += x;
      mean /= static_cast<double>(p.size());
      double sum = 0.0;
      for (const auto& x : p) sum += (x - mean).squaredNorm();
      return std::sqrt(sum / static_cast<double>(p.size()));
    };
    constexpr double kMinSpread = 1e-6;  // [m]
    for (const auto& [name, points] : {std::pair{"ground truth", &p_gt}, std::pair{"estimate", &p_est}}) {
      if (spread(*points) < kMinSpread) {
        throw std::invalid_argument(fmt::format("sim3 alignment: the {} does not move (positions spread {:.3g} m "
                                                "about their mean): its scale is undefined; use --align se3",
                                                name, spread(*points)));
      }
    }
  }
  if (alignment != Alignment::kNone) m.transform = umeyama_alignment(p_est, p_gt, alignment == Alignment::kSim3);
  m.aligned_errors.reserve(gt.size());
  m.unaligned_errors.reserve(gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) {
    m.unaligned_errors.push_back((p_gt[i] - p_est[i]).norm());
    m.aligned_errors.push_back((p_gt[i] - m.transform.apply(p_est[i])).norm());
  }
  m.aligned = error_stats(m.aligned_errors);
  m.unaligned = error_stats(m.unaligned_errors);
  return m;
}

// ---------------------------------------------------------------------------
// RPE
// ---------------------------------------------------------------------------

RpeMetrics compute_rpe(const std::vector<Pose>& gt, const std::vector<Pose>& est, std::size_t delta) {
  require_same_size(gt, est, "RPE");
  if (delta == 0) throw std::invalid_argument("RPE: delta must be positive");
  RpeMetrics m;
  m.delta = delta;
  for (std::size_t i = 0; i + delta < gt.size(); ++i) {
    const Matrix4 error = relative(gt[i], gt[i + delta]).inverse() * relative(est[i], est[i + delta]);
    m.trans_errors_m.push_back(error.block<3, 1>(0, 3).norm());
    m.rot_errors_deg.push_back(kRadToDeg * angle_of(error));
  }
  m.trans = error_stats(m.trans_errors_m);
  m.rot = error_stats(m.rot_errors_deg);
  m.trans_rmse_m = m.trans.rmse;
  m.rot_rmse_deg = m.rot.rmse;
  return m;
}

// ---------------------------------------------------------------------------
// Scale bias
// ---------------------------------------------------------------------------

namespace {

/// Ground-truth motions over consecutive windows of `delta` frames: the
/// translation of inv(G_i) G_{i+delta} for i = 0, delta, 2 delta, ...
template <class Visit>
void for_each_window(const std::vector<Pose>& gt, std::size_t delta, Visit&& visit) {
  for (std::size_t i = 0; i + delta < gt.size(); i += delta) {
    visit(i, Eigen::Vector3d(relative(gt[i], gt[i + delta]).block<3, 1>(0, 3)));
  }
}

constexpr double kMinWindowLength = 1e-3;  // [m] a window shorter than this has no direction

}  // namespace

Eigen::Vector3d body_up_axis(const std::vector<Pose>& gt, std::size_t delta) {
  if (delta == 0) throw std::invalid_argument("scale bias: delta must be positive");
  Eigen::Vector3d along = Eigen::Vector3d::Zero();
  for_each_window(gt, delta, [&](std::size_t, const Eigen::Vector3d& g) { along += g.cwiseAbs(); });
  Eigen::Index axis = 0;
  if (along.maxCoeff(&axis) <= 0.0) return Eigen::Vector3d::Zero();
  if (axis == 2) return -Eigen::Vector3d::UnitY();  // camera frame: z forward, y down
  if (axis == 0) return Eigen::Vector3d::UnitZ();   // LiDAR frame: x forward, z up
  return Eigen::Vector3d::Zero();
}

ScaleBias compute_scale_bias(const std::vector<Pose>& gt, const std::vector<Pose>& est, std::size_t delta) {
  require_same_size(gt, est, "scale bias");
  ScaleBias bias;
  bias.delta = delta;
  bias.body_up = body_up_axis(gt, delta);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();  // forward, lateral, vertical
  for_each_window(gt, delta, [&](std::size_t i, const Eigen::Vector3d& g) {
    const double length = g.norm();
    if (length < kMinWindowLength) return;
    const Eigen::Vector3d d = Eigen::Vector3d(relative(est[i], est[i + delta]).block<3, 1>(0, 3)) - g;
    const Eigen::Vector3d forward = g / length;
    const Eigen::Vector3d up = bias.body_up - bias.body_up.dot(forward) * forward;
    const double up_norm = up.norm();
    sum[0] += d.dot(forward);
    if (up_norm > 1e-6) {
      const Eigen::Vector3d vertical = up / up_norm;
      sum[1] += d.dot(vertical.cross(forward));
      sum[2] += d.dot(vertical);
    }
    bias.length_m += length;
    ++bias.windows;
  });
  const bool any = bias.windows > 0;
  const bool has_up = any && bias.body_up.squaredNorm() > 0.0;
  bias.forward_percent = any ? 100.0 * sum[0] / bias.length_m : kNaN;
  bias.lateral_percent = has_up ? 100.0 * sum[1] / bias.length_m : kNaN;
  bias.vertical_percent = has_up ? 100.0 * sum[2] / bias.length_m : kNaN;
  return bias;
}

// ---------------------------------------------------------------------------
// ATE per axis
// ---------------------------------------------------------------------------

AteAxes compute_ate_axes(const std::vector<Pose>& gt, const std::vector<Pose>& est, const AteMetrics& ate,
                         const Eigen::Vector3d& body_up) {
  require_same_size(gt, est, "ATE per axis");
  AteAxes axes;
  // The forward axis of the two conventions body_up_axis() knows.
  Eigen::Vector3d forward = Eigen::Vector3d::Zero();
  if (body_up == -Eigen::Vector3d::UnitY()) forward = Eigen::Vector3d::UnitZ();
  if (body_up == Eigen::Vector3d::UnitZ()) forward = Eigen::Vector3d::UnitX();
  if (gt.empty() || forward.squaredNorm() == 0.0) {
    axes.sideways_m = axes.vertical_m = axes.forward_m = kNaN;
    return axes;
  }
  const Eigen::Vector3d left = body_up.cross(forward);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();  // sideways, vertical, forward
  for (std::size_t i = 0; i < gt.size(); ++i) {
    const Eigen::Vector3d error = gt[i].translation() - ate.transform.apply(Eigen::Vector3d(est[i].translation()));
    // Into the pose's frame: R^T, as the frame's rotation is orthonormal to ~1e-6.
    const Eigen::Vector3d body = gt[i].linear().transpose() * error;
    sum += Eigen::Vector3d(body.dot(left), body.dot(body_up), body.dot(forward)).cwiseAbs2();
  }
  const Eigen::Vector3d rms = (sum / static_cast<double>(gt.size())).cwiseSqrt();
  axes.sideways_m = rms[0];
  axes.vertical_m = rms[1];
  axes.forward_m = rms[2];
  return axes;
}

// ---------------------------------------------------------------------------
// Everything
// ---------------------------------------------------------------------------

TrajectoryEvaluation evaluate_trajectories(const std::vector<Pose>& gt, const std::vector<Pose>& est,
                                           const EvaluationOptions& options) {
  TrajectoryEvaluation ev;
  ev.gt_poses = gt.size();
  ev.est_poses = est.size();
  const std::size_t n = std::min(gt.size(), est.size());
  if (n == 0) {
    throw std::invalid_argument(fmt::format("nothing to evaluate: ground truth has {} poses, the estimate {}",
                                            gt.size(), est.size()));
  }
  if (gt.size() != est.size()) {
    ev.warnings.push_back(fmt::format(
        "ground truth has {} poses but the estimate {}: evaluating the first {} poses only", gt.size(), est.size(), n));
  }
  ev.evaluated_poses = n;
  const std::vector<Pose> gt_common(gt.begin(), gt.begin() + static_cast<std::ptrdiff_t>(n));
  const std::vector<Pose> est_common(est.begin(), est.begin() + static_cast<std::ptrdiff_t>(n));

  ev.gt_length_m = trajectory_distances(gt_common).back();
  ev.kitti = compute_kitti_metrics(gt_common, est_common, options.kitti);
  if (ev.kitti.segments == 0) {
    ev.warnings.push_back(fmt::format("ground truth path ({:.1f} m) is shorter than the shortest KITTI segment: "
                                      "no KITTI relative error",
                                      ev.gt_length_m));
  }
  ev.ate = compute_ate(gt_common, est_common, options.alignment);
  ev.rpe = compute_rpe(gt_common, est_common, options.rpe_delta);
  ev.bias = compute_scale_bias(gt_common, est_common, options.bias_delta);
  ev.ate_axes = compute_ate_axes(gt_common, est_common, ev.ate, ev.bias.body_up);
  return ev;
}

}  // namespace saloam
