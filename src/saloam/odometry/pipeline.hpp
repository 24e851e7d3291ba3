#pragma once
// The odometry pipeline (paper Sec. III-B): per frame, feature extraction,
// constant-velocity prediction and de-skewing, semantic downsampling,
// scan-to-local-map registration and the local-map update. Composable: the
// SLAM pipeline and the demo feed it frames and read its poses.

#include <memory>
#include <vector>

#include <tbb/task_arena.h>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/odometry/features.hpp"
#include "saloam/odometry/local_map.hpp"
#include "saloam/odometry/registration.hpp"

namespace saloam {

/// Wall-clock time of each stage of one frame [ms].
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

class OdometryPipeline {
 public:
  explicit OdometryPipeline(OdometryConfig config);
  ~OdometryPipeline();
  OdometryPipeline(const OdometryPipeline&) = delete;
  OdometryPipeline& operator=(const OdometryPipeline&) = delete;

  /// Registers the next scan; returns its pose T_world<-sensor (world = the
  /// first scan's sensor frame at its pose instant). Labels are used when the
  /// cloud has them and semantics are on; otherwise everything is one class.
  Pose register_frame(const LabelledCloud& cloud, double timestamp);

  [[nodiscard]] const std::vector<Pose>& poses() const { return poses_; }
  [[nodiscard]] const std::vector<double>& timestamps() const { return timestamps_; }
  [[nodiscard]] const std::vector<FrameTimings>& timings() const { return timings_; }
  [[nodiscard]] const FrameStats& last_frame_stats() const { return last_stats_; }
  [[nodiscard]] const SemanticLocalMap& local_map() const { return map_; }
  /// Features of the last frame in the world frame (after downsampling).
  [[nodiscard]] const ScanFeatures& last_features_world() const { return last_world_; }
  [[nodiscard]] const OdometryConfig& config() const { return config_; }

 private:
  Pose process(const LabelledCloud& cloud, double timestamp);

  OdometryConfig config_;
  RegistrationSettings settings_;
  ClassVoxelSizes voxel_sizes_;
  SemanticLocalMap map_;
  std::unique_ptr<tbb::task_arena> arena_;
  std::vector<Pose> poses_;        ///< reported: at pose_time_in_sweep, world = first pose
  std::vector<Pose> sweep_poses_;  ///< internal: mid-sweep poses (de-skew reference)
  Pose world_from_first_sweep_ = Pose::Identity();
  std::vector<double> timestamps_;
  std::vector<FrameTimings> timings_;
  FrameStats last_stats_;
  ScanFeatures last_world_;
  ScanFeatures first_raw_;  ///< first frame's features before de-skewing (bootstrap)
};

}  // namespace saloam
