#include "saloam/odometry/start_up.hpp"

#include <algorithm>
#include <cmath>

#include "saloam/core/lie.hpp"
#include "saloam/odometry/deskew.hpp"

namespace saloam {

namespace {
// Frame 1's registrations get re-association rounds until its pose moves
// less than this (a whole frame's travel is more than the few rounds that
// suffice from a constant-velocity prediction: they stopped 0.9 m short along
// a hedge-lined street, and every later pose and every loop against frame 0
// would inherit the error).
constexpr int kOuterIterations = 10;
constexpr double kSettledTranslation = 0.01;           // [m]
constexpr double kSettledRotation = 0.1 * M_PI / 180;  // [rad]
}  // namespace

StartUp::StartUp(const OdometryConfig& config, const ClassVoxelSizes& voxel_sizes)
    : config_(config),
      coarse_map_(config.local_map_frames, voxel_sizes, kSearchRadius, map_voxel_point(config)) {}

void StartUp::keep_first_frame(const ScanFeatures& measured, const Pose& sweep_pose) {
  first_ = measured;
  first_sweep_pose_ = sweep_pose;
  coarse_map_.add_frame(transformed(measured.edges, sweep_pose), transformed(measured.planars, sweep_pose));
}

RegistrationResult StartUp::register_second_frame(ScanFeatures& features, const ScanFeatures& measured,
                                                  const Pose& initial, double period,
                                                  const RegistrationSettings& steady, SemanticLocalMap& map,
                                                  int& rounds) const {
  RegistrationSettings settings = steady;
  settings.outer_iterations = std::max(settings.outer_iterations, kOuterIterations);
  settings.far_outer_iterations = 0;  // its own rounds: the guess is known to be far off
  settings.reassociation_min_translation = std::max(settings.reassociation_min_translation, kSettledTranslation);
  settings.reassociation_min_rotation = std::max(settings.reassociation_min_rotation, kSettledRotation);
  auto fit = [&](const SemanticLocalMap& to, const Pose& from, const RegistrationSettings& with) {
    RegistrationResult result = register_scan(features, to, from, with, FeatureRefresh{});
    rounds += result.associations;
    return result;
  };
  RegistrationSettings coarse = settings;
  coarse.max_correspondence_distance = kSearchRadius;
  const RegistrationResult rough = fit(coarse_map_, initial, coarse);
  RegistrationResult result = fit(map, rough.ok ? rough.pose : initial, settings);
  if (!config_.deskew || !result.ok) return result;
  // The motion of both sweeps is now known: de-skew them with it and restart
  // the map from frame 0.
  const double mid = 0.5 * config_.features.sweep_duration;
  const Vector6d motion = se3_log(first_sweep_pose_.inverse() * result.pose);
  const ScanFeatures first = deskewed(first_, motion, period, mid);
  map = SemanticLocalMap::from_config(config_);
  map.add_frame(transformed(first.edges, first_sweep_pose_), transformed(first.planars, first_sweep_pose_));
  features = deskewed(measured, motion, period, mid);
  return fit(map, result.pose, settings);
}

}  // namespace saloam
