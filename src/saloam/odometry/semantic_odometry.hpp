#pragma once
// The semantic-assisted odometry (paper Sec. III-B). Per frame, a few named
// steps: predict the motion (constant velocity); extract LOAM features with
// their classes, heights along up; downsample per class and de-skew;
// register to the local map (semantic ICP, de-skewing again as the estimate
// moves); add the frame to the local map; report the pose at the scan's pose
// instant; let the scan refine up. The first two frames, before a motion is
// known, are the start-up's (start_up.hpp); up is set at the first frame
// (gravity.hpp).
// The SLAM system feeds it frames and reads its poses and features.

#include <memory>
#include <optional>
#include <vector>

#include <tbb/task_arena.h>

#include "saloam/core/config.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/types.hpp"
#include "saloam/odometry/features.hpp"
#include "saloam/odometry/gravity.hpp"
#include "saloam/odometry/local_map.hpp"
#include "saloam/odometry/registration.hpp"
#include "saloam/odometry/start_up.hpp"

namespace saloam {

/// Time of each stage of one frame [ms]: wall-clock, or CPU time of the
/// calling thread (the stage's cost when the odometry runs on one thread).
struct FrameTimings {
  double features_ms = 0.0;
  double deskew_downsample_ms = 0.0;
  double registration_ms = 0.0;
  double map_update_ms = 0.0;
  [[nodiscard]] double total_ms() const {
    return features_ms + deskew_downsample_ms + registration_ms + map_update_ms;
  }
};

struct FrameStats {
  std::size_t edge_features = 0;    ///< after downsampling
  std::size_t planar_features = 0;  ///< after downsampling
  RegistrationResult registration;  ///< the final registration of the frame
  int association_rounds = 0;       ///< over all registrations of the frame (refinements included)
  std::size_t map_edge_points = 0;    ///< local map after the update
  std::size_t map_planar_points = 0;  ///< local map after the update
};

class SemanticOdometry {
 public:
  explicit SemanticOdometry(OdometryConfig config);
  ~SemanticOdometry();
  SemanticOdometry(const SemanticOdometry&) = delete;
  SemanticOdometry& operator=(const SemanticOdometry&) = delete;

  /// Registers the next scan; returns its pose T_world<-sensor (world = the
  /// first scan's sensor frame at its pose instant). Labels are used when the
  /// cloud has them and semantics are on; otherwise everything is one class.
  Pose register_frame(const LabelledCloud& cloud, double timestamp);

  [[nodiscard]] const std::vector<Pose>& poses() const { return poses_; }
  [[nodiscard]] const std::vector<double>& timestamps() const { return timestamps_; }
  [[nodiscard]] const std::vector<FrameTimings>& timings() const { return timings_; }
  /// Thread CPU time per stage (with more than one thread, the workers' time is not counted).
  [[nodiscard]] const std::vector<FrameTimings>& cpu_timings() const { return cpu_timings_; }
  [[nodiscard]] const FrameStats& last_frame_stats() const { return last_stats_; }
  [[nodiscard]] const SemanticLocalMap& local_map() const { return map_; }
  /// Features of the last frame (downsampled, de-skewed, classes grouped as
  /// matched) in its sensor frame at the reported pose instant: poses().back()
  /// maps them into the world.
  [[nodiscard]] const ScanFeatures& last_features() const { return last_features_; }
  [[nodiscard]] const OdometryConfig& config() const { return config_; }
  /// w^l used for the next frame, per class index (matched class groups:
  /// the group's index): the configured weights, scaled when
  /// adaptive_class_weights is on.
  [[nodiscard]] const std::array<double, kNumClassIndices>& class_weights() const { return settings_.class_weight; }
  /// Up in the world frame (the first scan's sensor frame at its pose
  /// instant; the sensor's z before the first frame), and where it came from.
  [[nodiscard]] Eigen::Vector3d up() const;
  [[nodiscard]] GravityReport gravity() const;

 private:
  /// Constant-velocity prediction of the next mid-sweep pose.
  struct MotionPrediction {
    Pose pose = Pose::Identity();
    Vector6d motion = Vector6d::Zero();  ///< expected twist over one frame
    double period = 0.1;                 ///< [s] time since the previous frame
    bool motion_known = false;           ///< from two earlier frames (not for frames 0 and 1)
  };

  Pose process(const LabelledCloud& cloud, double timestamp);
  /// Features with heights along `up` (sensor frame).
  ScanFeatures extract_frame_features(const LabelledCloud& cloud, const Eigen::Vector3d& up) const;
  [[nodiscard]] bool uses_labels(const LabelledCloud& cloud) const { return config_.use_semantics && cloud.has_labels; }
  MotionPrediction predict_motion(double timestamp) const;
  /// Downsamples `measured` in place and returns it de-skewed with the predicted motion.
  ScanFeatures downsample_and_deskew(ScanFeatures& measured, const MotionPrediction& prediction) const;
  /// Registers `features` to the local map; de-skews them again from
  /// `measured` as the estimate moves. Returns the mid-sweep pose.
  Pose register_to_map(ScanFeatures& features, const ScanFeatures& measured, const MotionPrediction& prediction);
  /// De-skews the scan again from `measured` between registration rounds (none before the motion is known).
  FeatureRefresh deskew_refresh(const ScanFeatures& measured, const MotionPrediction& prediction) const;
  void update_map(const ScanFeatures& features, const Pose& sweep_pose);
  /// Adaptive class weights: folds the frame's per-class residuals into the
  /// running variances and sets settings_.class_weight from them.
  void update_class_weights(const RegistrationResult& fit);
  /// Stores the frame and returns its pose at the pose instant.
  Pose record_frame(ScanFeatures features, const Pose& sweep_pose, double timestamp, const FrameTimings& timing,
                    const FrameTimings& cpu_timing);

  OdometryConfig config_;
  RegistrationSettings settings_;
  std::array<double, kNumClassIndices> configured_weights_{};  ///< w^l from the config
  /// Exponentially averaged per-class squared residuals and their degrees of freedom.
  std::array<double, kNumClassIndices> class_squared_residuals_{}, class_dof_{};
  ClassVoxelSizes voxel_sizes_;
  SemanticLocalMap map_;
  std::unique_ptr<tbb::task_arena> arena_;
  std::vector<Pose> poses_;        ///< reported: at pose_time_in_sweep, world = first pose
  std::vector<Pose> sweep_poses_;  ///< internal: mid-sweep poses (de-skew reference)
  Pose world_from_first_sweep_ = Pose::Identity();
  std::vector<double> timestamps_;
  std::vector<FrameTimings> timings_;
  std::vector<FrameTimings> cpu_timings_;
  FrameStats last_stats_;
  ScanFeatures last_features_;
  std::optional<StartUp> start_up_;  ///< frames 0 and 1
  /// Up in the internal world (the first scan's mid-sweep frame, where
  /// sweep_poses_ live); up() turns it into the reported world.
  GravityTracker gravity_;
};

}  // namespace saloam
