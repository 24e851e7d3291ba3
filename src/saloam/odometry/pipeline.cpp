#include "saloam/odometry/pipeline.hpp"

#include <chrono>
#include <thread>

#include "saloam/core/lie.hpp"
#include "saloam/odometry/deskew.hpp"

namespace saloam {

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

FeatureCloud transformed(const FeatureCloud& cloud, const Pose& T) {
  FeatureCloud out = cloud;
  for (auto& p : out.points) p = T * p;
  return out;
}
}  // namespace

OdometryPipeline::OdometryPipeline(OdometryConfig config)
    : config_(std::move(config)),
      settings_(RegistrationSettings::from_config(config_)),
      voxel_sizes_(class_voxel_sizes(config_)),
      map_(config_.local_map_frames, voxel_sizes_) {
  if (config_.threads != 1) {
    const int threads = config_.threads > 0 ? config_.threads
                                            : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    arena_ = std::make_unique<tbb::task_arena>(threads);
    settings_.parallel = threads > 1;
  }
}

OdometryPipeline::~OdometryPipeline() = default;

Pose OdometryPipeline::register_frame(const LabelledCloud& cloud, double timestamp) {
  if (arena_) return arena_->execute([&] { return process(cloud, timestamp); });
  return process(cloud, timestamp);
}

Pose OdometryPipeline::process(const LabelledCloud& cloud, double timestamp) {
  FrameTimings timing;
  auto t0 = Clock::now();
  const bool use_labels = config_.use_semantics && cloud.has_labels;
  ScanFeatures features = extract_features(cloud, config_.features, use_labels);
  timing.features_ms = ms_since(t0);

  // Constant-velocity model: the motion of the last frame, rescaled to this
  // frame's time step, predicts the pose and the motion during the sweep.
  t0 = Clock::now();
  const std::size_t k = poses_.size();
  Pose prediction = k > 0 ? poses_.back() : Pose::Identity();
  Vector6d motion = Vector6d::Zero();
  double period = config_.features.sweep_duration;
  if (k >= 2) {
    const double dt_prev = timestamps_[k - 1] - timestamps_[k - 2];
    const double dt = timestamp - timestamps_[k - 1];
    const Vector6d last_motion = se3_log(poses_[k - 2].inverse() * poses_[k - 1]);
    const double scale = (dt_prev > 1e-6 && dt > 1e-6) ? dt / dt_prev : 1.0;
    motion = scale * last_motion;
    if (dt > 1e-6) period = dt;
    prediction = orthonormalized(poses_.back() * se3_exp(motion));
  }
  if (config_.deskew && k >= 2) {
    deskew(features.edges, motion, period, config_.features.pose_time_in_sweep);
    deskew(features.planars, motion, period, config_.features.pose_time_in_sweep);
  }
  // The second frame has no motion history: keep its raw features to de-skew
  // it (and the first frame) once its motion is known.
  ScanFeatures raw;
  if (config_.deskew && k <= 1) raw = features;
  features.edges = voxel_downsample(features.edges, voxel_sizes_);
  features.planars = voxel_downsample(features.planars, voxel_sizes_);
  timing.deskew_downsample_ms = ms_since(t0);

  t0 = Clock::now();
  last_stats_ = FrameStats{};
  last_stats_.edge_features = features.edges.size();
  last_stats_.planar_features = features.planars.size();
  Pose pose = prediction;
  if (!map_.empty()) {
    last_stats_.registration = register_scan(features.edges, features.planars, map_, prediction, settings_);
    pose = last_stats_.registration.pose;
    if (config_.deskew && k == 1 && last_stats_.registration.ok) {
      // Bootstrap: de-skew the first two frames with the motion just
      // estimated, rebuild the map from the first and register again.
      const Vector6d first_motion = se3_log(poses_[0].inverse() * pose);
      const double pt = config_.features.pose_time_in_sweep;
      ScanFeatures first = first_raw_;
      deskew(first.edges, first_motion, period, pt);
      deskew(first.planars, first_motion, period, pt);
      map_ = SemanticLocalMap(config_.local_map_frames, voxel_sizes_);
      map_.add_frame(transformed(voxel_downsample(first.edges, voxel_sizes_), poses_[0]),
                     transformed(voxel_downsample(first.planars, voxel_sizes_), poses_[0]));
      deskew(raw.edges, first_motion, period, pt);
      deskew(raw.planars, first_motion, period, pt);
      features.edges = voxel_downsample(raw.edges, voxel_sizes_);
      features.planars = voxel_downsample(raw.planars, voxel_sizes_);
      last_stats_.registration = register_scan(features.edges, features.planars, map_, pose, settings_);
      pose = last_stats_.registration.pose;
    }
  }
  if (config_.deskew && k == 0) first_raw_ = std::move(raw);
  if (k >= 1) first_raw_ = ScanFeatures{};
  pose = orthonormalized(pose);
  timing.registration_ms = ms_since(t0);

  t0 = Clock::now();
  last_world_.edges = transformed(features.edges, pose);
  last_world_.planars = transformed(features.planars, pose);
  map_.add_frame(last_world_.edges, last_world_.planars);
  timing.map_update_ms = ms_since(t0);

  poses_.push_back(pose);
  timestamps_.push_back(timestamp);
  timings_.push_back(timing);
  return pose;
}

}  // namespace saloam
