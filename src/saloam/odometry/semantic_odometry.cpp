#include "saloam/odometry/semantic_odometry.hpp"

#include <algorithm>
#include <thread>

#include "saloam/core/lie.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/odometry/deskew.hpp"

namespace saloam {

namespace {
// A registered sweep motion that differs from the one the scan was de-skewed
// with by more than this moves points by more than ~1 cm: de-skew again.
constexpr double kRedeskewTranslation = 0.01;           // [m per frame]
constexpr double kRedeskewRotation = 0.1 * M_PI / 180;  // [rad per frame]
// The second frame is registered from the first frame's pose (no motion is
// known yet), possibly a whole frame's travel away, beyond the correspondence
// distance: the few re-association rounds that suffice from a
// constant-velocity prediction can stop short of it, and every later pose and
// every loop against frame 0 would inherit the error. It gets rounds until
// the pose settles.
constexpr int kBootstrapOuterIterations = 10;
// Before that, a coarse registration against frame 0 alone searches
// correspondences this far [m] (a frame's travel at 30 m/s): along a street
// lined with hedges and parked cars, standing still fits the walls as well as
// the true motion does, and only the few features across the street's
// direction (poles, corners, car ends) tell them apart, up to a frame's
// travel away.
constexpr double kBootstrapSearchRadius = 3.0;
// Adaptive class weights: each frame's residual sums are added to the
// running ones after scaling those by kResidualMemory (about ten frames of
// memory); a class needs kMinClassDof degrees of freedom before its weight
// moves, and the variance ratio is bounded to [1 / kMaxWeightRatio, kMaxWeightRatio].
constexpr double kResidualMemory = 0.9;
constexpr double kMinClassDof = 50;
constexpr double kMaxWeightRatio = 4.0;
constexpr double kBootstrapSettledTranslation = 0.01;           // [m]
constexpr double kBootstrapSettledRotation = 0.1 * M_PI / 180;  // [rad]

}  // namespace

SemanticOdometry::SemanticOdometry(OdometryConfig config)
    : config_(std::move(config)),
      settings_(RegistrationSettings::from_config(config_)),
      voxel_sizes_(class_voxel_sizes(config_)),
      map_(SemanticLocalMap::from_config(config_)) {
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
  ScanFeatures measured = extract_frame_features(cloud);
  const StageTime features_time = timer.lap();
  const MotionPrediction prediction = predict_motion(timestamp);
  ScanFeatures features = downsample_and_deskew(measured, prediction);
  const StageTime deskew_time = timer.lap();
  const Pose sweep_pose = align(features, measured, prediction);
  if (config_.adaptive_class_weights && config_.use_semantics) update_class_weights(last_stats_.registration);
  const StageTime registration_time = timer.lap();
  update_map(features, sweep_pose);
  const StageTime map_time = timer.lap();
  return record_frame(std::move(features), sweep_pose, timestamp,
                      {features_time.wall_ms, deskew_time.wall_ms, registration_time.wall_ms, map_time.wall_ms},
                      {features_time.cpu_ms, deskew_time.cpu_ms, registration_time.cpu_ms, map_time.cpu_ms});
}

ScanFeatures SemanticOdometry::extract_frame_features(const LabelledCloud& cloud) const {
  const bool use_labels = config_.use_semantics && cloud.has_labels;
  ScanFeatures features = extract_features(cloud, config_.features, use_labels, settings_.parallel);
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
  if (k >= 2) {
    // Constant velocity: the last frame's motion, rescaled to this time step.
    const double dt_prev = timestamps_[k - 1] - timestamps_[k - 2];
    const double dt = timestamp - timestamps_[k - 1];
    const double scale = (dt_prev > 1e-6 && dt > 1e-6) ? dt / dt_prev : 1.0;
    p.motion = scale * se3_log(sweep_poses_[k - 2].inverse() * sweep_poses_[k - 1]);
    p.pose = orthonormalized(sweep_poses_.back() * se3_exp(p.motion));
  }
  return p;
}

namespace {
ScanFeatures deskewed(const ScanFeatures& scan, const Vector6d& frame_motion, double period, double reference_time) {
  ScanFeatures out = scan;
  deskew(out.edges, frame_motion, period, reference_time);
  deskew(out.planars, frame_motion, period, reference_time);
  return out;
}
}  // namespace

// Features are downsampled as measured and de-skewed afterwards, so that
// de-skewing again (in align) moves the same points. The first two frames
// are de-skewed only once a motion is known (the bootstrap in align).
ScanFeatures SemanticOdometry::downsample_and_deskew(ScanFeatures& measured, const MotionPrediction& prediction) const {
  measured.edges = voxel_downsample(measured.edges, voxel_sizes_);
  measured.planars = voxel_downsample(measured.planars, voxel_sizes_);
  if (!config_.deskew || sweep_poses_.size() < 2) return measured;
  return deskewed(measured, prediction.motion, prediction.period, 0.5 * config_.features.sweep_duration);
}

Pose SemanticOdometry::align(ScanFeatures& features, ScanFeatures& measured, const MotionPrediction& prediction) {
  const std::size_t k = sweep_poses_.size();
  const bool deskewing = config_.deskew;
  const double mid = 0.5 * config_.features.sweep_duration;
  last_stats_ = FrameStats{};
  last_stats_.edge_features = features.edges.size();
  last_stats_.planar_features = features.planars.size();
  // The motion during this sweep is better known from the registration's
  // current estimate than from the previous frame (which lags when the turn
  // rate changes): between rounds, when the two differ, the scan is de-skewed
  // again with the estimate. Without this the loop velocity -> de-skew -> pose
  // builds up errors in turns.
  Vector6d deskew_motion = prediction.motion;
  FeatureRefresh refresh;
  if (deskewing && k >= 2) {
    refresh = [&](const Pose& current, ScanFeatures& scan) {
      const Vector6d estimated = se3_log(sweep_poses_[k - 1].inverse() * current);
      const Vector6d change = estimated - deskew_motion;
      if (change.head<3>().norm() <= kRedeskewTranslation && change.tail<3>().norm() <= kRedeskewRotation) {
        return false;
      }
      deskew_motion = estimated;
      scan = deskewed(measured, deskew_motion, prediction.period, mid);
      return true;
    };
  }
  RegistrationSettings settings = settings_;
  if (k == 1) {
    settings.outer_iterations = std::max(settings.outer_iterations, kBootstrapOuterIterations);
    settings.reassociation_min_translation = std::max(settings.reassociation_min_translation, kBootstrapSettledTranslation);
    settings.reassociation_min_rotation = std::max(settings.reassociation_min_rotation, kBootstrapSettledRotation);
  }
  auto register_from = [&](const Pose& initial) {
    RegistrationResult result = register_scan(features, map_, initial, settings, refresh);
    last_stats_.association_rounds += result.associations;
    return result;
  };
  const Pose start = k == 1 ? coarse_start(features, prediction.pose, settings, refresh) : prediction.pose;
  if (k >= 1) bootstrap_map_.reset();
  Pose pose = prediction.pose;
  if (!map_.empty()) {
    last_stats_.registration = register_from(start);
    pose = last_stats_.registration.pose;
    if (deskewing && k == 1 && last_stats_.registration.ok) {
      // Bootstrap: de-skew the first two frames with the motion just
      // estimated, rebuild the map from the first and register again.
      const Vector6d first_motion = se3_log(sweep_poses_[0].inverse() * pose);
      const ScanFeatures first = deskewed(first_raw_, first_motion, prediction.period, mid);
      map_ = SemanticLocalMap::from_config(config_);
      map_.add_frame(transformed(first.edges, sweep_poses_[0]), transformed(first.planars, sweep_poses_[0]));
      revised_first_ = first;  // mid-sweep frame of sweep 0; moved to its pose instant in record_frame
      features = deskewed(measured, first_motion, prediction.period, mid);
      last_stats_.registration = register_from(pose);
      pose = last_stats_.registration.pose;
    }
  }
  if (deskewing && k == 0) first_raw_ = std::move(measured);
  if (k >= 1) first_raw_ = ScanFeatures{};
  return orthonormalized(pose);
}

// The second frame's registration against frame 0 alone, searched up to
// kBootstrapSearchRadius: its pose, or `initial` when it finds too few
// correspondences.
Pose SemanticOdometry::coarse_start(ScanFeatures& features, const Pose& initial, const RegistrationSettings& settings,
                                    const FeatureRefresh& refresh) {
  if (!bootstrap_map_) return initial;
  RegistrationSettings coarse = settings;
  coarse.max_correspondence_distance = kBootstrapSearchRadius;
  const RegistrationResult result = register_scan(features, *bootstrap_map_, initial, coarse, refresh);
  last_stats_.association_rounds += result.associations;
  return result.ok ? result.pose : initial;
}

void SemanticOdometry::update_map(const ScanFeatures& features, const Pose& sweep_pose) {
  const FeatureCloud edges = transformed(features.edges, sweep_pose);
  const FeatureCloud planars = transformed(features.planars, sweep_pose);
  map_.add_frame(edges, planars);
  if (sweep_poses_.empty()) {  // frame 0, for the second frame's coarse registration
    bootstrap_map_.emplace(config_.local_map_frames, voxel_sizes_, kBootstrapSearchRadius, map_voxel_point(config_));
    bootstrap_map_->add_frame(edges, planars);
  }
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
    if (k == 1) {
      world_from_first_sweep_ = orthonormalized(se3_exp(a * xi));
      // Frame 0's pose P_0 = I = C * exp(-a xi_0): its mid-sweep frame maps to its pose instant by C.
      if (revised_first_) {
        revised_first_->edges = transformed(revised_first_->edges, world_from_first_sweep_);
        revised_first_->planars = transformed(revised_first_->planars, world_from_first_sweep_);
      }
    }
    pose_from_sweep = se3_exp(-a * xi);
    poses_.push_back(orthonormalized(world_from_first_sweep_ * sweep_poses_.front().inverse() * sweep_pose * pose_from_sweep));
  }
  const Pose to_pose_instant = pose_from_sweep.inverse();
  last_features_.edges = transformed(features.edges, to_pose_instant);
  last_features_.planars = transformed(features.planars, to_pose_instant);
  return poses_.back();
}

}  // namespace saloam
