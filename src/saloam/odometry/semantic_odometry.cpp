#include "saloam/odometry/semantic_odometry.hpp"

#include <algorithm>
#include <thread>

#include <spdlog/spdlog.h>

#include "saloam/core/lie.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/odometry/deskew.hpp"

namespace saloam {

namespace {
// A registered sweep motion that differs from the one the scan was de-skewed
// with by more than this moves points by more than ~1 cm: de-skew again.
constexpr double kRedeskewTranslation = 0.01;           // [m per frame]
constexpr double kRedeskewRotation = 0.1 * M_PI / 180;  // [rad per frame]
// Adaptive class weights: each frame's residual sums are added to the
// running ones after scaling those by kResidualMemory (about ten frames of
// memory); a class needs kMinClassDof degrees of freedom before its weight
// moves, and the variance ratio is bounded to [1 / kMaxWeightRatio, kMaxWeightRatio].
constexpr double kResidualMemory = 0.9;
constexpr double kMinClassDof = 50;
constexpr double kMaxWeightRatio = 4.0;
// A step between frames longer than this is a gap (a recording paused, a
// clock jump, a live run's long stall): the last motion is not carried
// across it (a 1 h jump extrapolated a car's 10 m/s to 36 km).
constexpr double kMaxExtrapolation = 1.0;  // [s]

}  // namespace

SemanticOdometry::SemanticOdometry(OdometryConfig config)
    : config_(std::move(config)),
      settings_(RegistrationSettings::from_config(config_)),
      voxel_sizes_(class_voxel_sizes(config_)),
      map_(SemanticLocalMap::from_config(config_)),
      start_up_(std::in_place, config_, voxel_sizes_),
      gravity_(config_.gravity) {
  configured_weights_ = settings_.class_weight;
  if (config_.threads != 1) {
    const int threads = config_.threads > 0 ? config_.threads
                                            : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    arena_ = std::make_unique<tbb::task_arena>(threads);
    settings_.parallel = threads > 1;
  }
}

SemanticOdometry::~SemanticOdometry() = default;

Pose SemanticOdometry::register_frame(const LabelledCloud& cloud, double timestamp) {
  if (arena_) return arena_->execute([&] { return process(cloud, timestamp); });
  return process(cloud, timestamp);
}

Pose SemanticOdometry::process(const LabelledCloud& cloud, double timestamp) {
  StageTimer timer;
  if (!gravity_.started()) gravity_.start(cloud, uses_labels(cloud));
  settings_.up = gravity_.up();
  const MotionPrediction prediction = predict_motion(timestamp);
  ScanFeatures measured = extract_frame_features(cloud, prediction.pose.linear().transpose() * gravity_.up());
  const StageTime features_time = timer.lap();
  ScanFeatures features = downsample_and_deskew(measured, prediction);
  const StageTime deskew_time = timer.lap();
  const Pose sweep_pose = register_to_map(features, measured, prediction);
  if (config_.adaptive_class_weights && config_.use_semantics) update_class_weights(last_stats_.registration);
  const StageTime registration_time = timer.lap();
  update_map(features, sweep_pose);
  if (!sweep_poses_.empty()) gravity_.observe(cloud, uses_labels(cloud), sweep_pose.linear(), sweep_poses_.size());
  const StageTime map_time = timer.lap();
  return record_frame(std::move(features), sweep_pose, timestamp,
                      {features_time.wall_ms, deskew_time.wall_ms, registration_time.wall_ms, map_time.wall_ms},
                      {features_time.cpu_ms, deskew_time.cpu_ms, registration_time.cpu_ms, map_time.cpu_ms});
}

ScanFeatures SemanticOdometry::extract_frame_features(const LabelledCloud& cloud, const Eigen::Vector3d& up) const {
  const bool use_labels = uses_labels(cloud);
  ScanFeatures features = extract_features(cloud, config_.features, use_labels, settings_.parallel, up);
  if (use_labels && config_.match_class_groups) {
    for (auto& c : features.edges.classes) c = class_group(c);
    for (auto& c : features.planars.classes) c = class_group(c);
  }
  return features;
}

// Internally every scan is de-skewed to, and registered at, mid-sweep: the
// correction is then symmetric in time, so an error in the assumed velocity
// distorts the scan without shifting it on average. De-skewing to the sweep
// start instead couples half the velocity error into the pose, and the
// constant-velocity loop (pose -> velocity -> de-skew -> pose) oscillates and
// diverges (measured on simulated data). The reported pose is moved to
// `pose_time_in_sweep` in record_frame().
SemanticOdometry::MotionPrediction SemanticOdometry::predict_motion(double timestamp) const {
  MotionPrediction p;
  const std::size_t k = sweep_poses_.size();
  p.pose = k > 0 ? sweep_poses_.back() : Pose::Identity();
  p.period = config_.features.sweep_duration;
  if (k >= 1 && timestamp - timestamps_[k - 1] > 1e-6) p.period = timestamp - timestamps_[k - 1];
  if (k >= 1 && timestamp - timestamps_[k - 1] > kMaxExtrapolation) {
    spdlog::warn("frame {}: {:.3f} s after the previous frame: a gap, across which the last motion is not carried (the "
                 "pose starts from the previous one)",
                 k, timestamp - timestamps_[k - 1]);
    return p;
  }
  if (k >= 2) {
    // Constant velocity: the last frame's motion, rescaled to this time step.
    const double dt_prev = timestamps_[k - 1] - timestamps_[k - 2];
    const double dt = timestamp - timestamps_[k - 1];
    const double scale = (dt_prev > 1e-6 && dt > 1e-6) ? dt / dt_prev : 1.0;
    p.motion = scale * se3_log(sweep_poses_[k - 2].inverse() * sweep_poses_[k - 1]);
    p.pose = orthonormalized(sweep_poses_.back() * se3_exp(p.motion));
    p.motion_known = true;
  }
  return p;
}

// Features are downsampled as measured and de-skewed afterwards, so that
// de-skewing again (in register_to_map) moves the same points. The first two
// frames are de-skewed only once their motion is known (StartUp).
ScanFeatures SemanticOdometry::downsample_and_deskew(ScanFeatures& measured, const MotionPrediction& prediction) const {
  measured.edges = voxel_downsample(measured.edges, voxel_sizes_);
  measured.planars = voxel_downsample(measured.planars, voxel_sizes_);
  if (!config_.deskew || !prediction.motion_known) return measured;
  return deskewed(measured, prediction.motion, prediction.period, 0.5 * config_.features.sweep_duration);
}

// Frame 0 has nothing to register to (its pose is the prediction, the
// world's origin), frame 1 is registered by the start-up, every later frame
// from the constant-velocity prediction.
Pose SemanticOdometry::register_to_map(ScanFeatures& features, const ScanFeatures& measured,
                                       const MotionPrediction& prediction) {
  last_stats_ = FrameStats{};
  last_stats_.edge_features = features.edges.size();
  last_stats_.planar_features = features.planars.size();
  if (map_.empty()) return orthonormalized(prediction.pose);
  if (start_up_) {
    last_stats_.registration = start_up_->register_second_frame(features, measured, prediction.pose, prediction.period,
                                                                settings_, map_, last_stats_.association_rounds);
    start_up_.reset();
  } else {
    last_stats_.registration =
        register_scan(features, map_, prediction.pose, settings_, deskew_refresh(measured, prediction));
    last_stats_.association_rounds += last_stats_.registration.associations;
  }
  return orthonormalized(last_stats_.registration.pose);
}

// The motion during this sweep is better known from the registration's
// current estimate than from the previous frame (which lags when the turn
// rate changes): between rounds, when the two differ, the scan is de-skewed
// again with the estimate. Without this the loop velocity -> de-skew -> pose
// builds up errors in turns.
FeatureRefresh SemanticOdometry::deskew_refresh(const ScanFeatures& measured, const MotionPrediction& prediction) const {
  if (!config_.deskew || !prediction.motion_known) return {};
  const Pose previous = sweep_poses_.back();
  const double mid = 0.5 * config_.features.sweep_duration;
  return [&measured, previous, mid, period = prediction.period, deskew_motion = prediction.motion](
             const Pose& current, ScanFeatures& scan) mutable {
    const Vector6d estimated = se3_log(previous.inverse() * current);
    const Vector6d change = estimated - deskew_motion;
    if (change.head<3>().norm() <= kRedeskewTranslation && change.tail<3>().norm() <= kRedeskewRotation) return false;
    deskew_motion = estimated;
    scan = deskewed(measured, deskew_motion, period, mid);
    return true;
  };
}

Eigen::Vector3d SemanticOdometry::up() const { return world_from_first_sweep_.linear() * gravity_.up(); }

GravityReport SemanticOdometry::gravity() const {
  GravityReport report = gravity_.report();
  const Eigen::Matrix3d to_world = world_from_first_sweep_.linear();
  report.up = to_world * report.up;
  if (report.scans_up) report.scans_up = to_world * *report.scans_up;
  return report;
}

void SemanticOdometry::update_map(const ScanFeatures& features, const Pose& sweep_pose) {
  map_.add_frame(transformed(features.edges, sweep_pose), transformed(features.planars, sweep_pose));
  if (sweep_poses_.empty()) start_up_->keep_first_frame(features, sweep_pose);  // as measured: its motion is unknown
  last_stats_.map_edge_points = map_.num_edge_points();
  last_stats_.map_planar_points = map_.num_planar_points();
}

void SemanticOdometry::update_class_weights(const RegistrationResult& fit) {
  if (!fit.ok) return;
  double squared = 0, dof = 0;
  for (int c = 0; c < kNumClassIndices; ++c) {
    class_squared_residuals_[c] = kResidualMemory * class_squared_residuals_[c] + fit.class_squared_residuals[c];
    class_dof_[c] = kResidualMemory * class_dof_[c] + fit.class_dof[c];
    squared += class_squared_residuals_[c];
    dof += class_dof_[c];
  }
  if (dof <= 0 || squared <= 0) return;
  const double pooled = squared / dof;
  for (int c = 0; c < kNumClassIndices; ++c) {
    double ratio = 1.0;
    if (class_dof_[c] >= kMinClassDof && class_squared_residuals_[c] > 0) {
      ratio = std::clamp(pooled / (class_squared_residuals_[c] / class_dof_[c]), 1.0 / kMaxWeightRatio, kMaxWeightRatio);
    }
    settings_.class_weight[c] = configured_weights_[c] * ratio;
  }
}

Pose SemanticOdometry::record_frame(ScanFeatures features, const Pose& sweep_pose, double timestamp,
                                    const FrameTimings& timing, const FrameTimings& cpu_timing) {
  const std::size_t k = sweep_poses_.size();
  const double period = k >= 1 && timestamp - timestamps_[k - 1] > 1e-6 ? timestamp - timestamps_[k - 1]
                                                                         : config_.features.sweep_duration;
  sweep_poses_.push_back(sweep_pose);
  timestamps_.push_back(timestamp);
  timings_.push_back(timing);
  cpu_timings_.push_back(cpu_timing);

  // Reported pose at `pose_time_in_sweep`: P_k = C * M_k * exp(-a * xi_k) with
  // M_k the mid-sweep pose, xi_k its frame motion and a = (mid - t_pose) / period.
  // C = exp(a * xi_1) makes P_0 the identity (the world is the first scan's
  // sensor frame at its pose instant); xi_0 := xi_1 (constant velocity).
  const double mid = 0.5 * config_.features.sweep_duration;
  const double a = config_.deskew ? (mid - config_.features.pose_time_in_sweep) / period : 0.0;
  Pose pose_from_sweep = Pose::Identity();  // exp(-a * xi_k): mid-sweep frame -> pose-instant frame
  if (k == 0 || a == 0.0) {
    poses_.push_back(k == 0 ? Pose::Identity() : sweep_poses_.front().inverse() * sweep_pose);
  } else {
    const Vector6d xi = se3_log(sweep_poses_[k - 1].inverse() * sweep_pose);
    if (k == 1) world_from_first_sweep_ = orthonormalized(se3_exp(a * xi));
    pose_from_sweep = se3_exp(-a * xi);
    poses_.push_back(orthonormalized(world_from_first_sweep_ * sweep_poses_.front().inverse() * sweep_pose * pose_from_sweep));
  }
  const Pose to_pose_instant = pose_from_sweep.inverse();
  last_features_.edges = transformed(features.edges, to_pose_instant);
  last_features_.planars = transformed(features.planars, to_pose_instant);
  return poses_.back();
}

}  // namespace saloam
