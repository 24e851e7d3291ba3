#pragma once
// The "handheld-walk" preset (issue #51): a person walks 60 s along a street
// with a LiDAR held up at head height, looking around. Its rotation changes
// within a sweep (look-arounds at up to ~190 deg/s, the gait's sway, the
// hand's shake), so the simulator samples its motion within every sweep
// rather than interpolating linearly between frames.
//
// Frames and units: T_W<-L (LiDAR x forward, z up as held level), W = the
// start's position and heading with z up (against gravity); t [s] from the
// start; metres, radians.

#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

class HandheldWalk {
 public:
  HandheldWalk();

  /// Seconds from the first frame to the last.
  [[nodiscard]] double duration() const { return duration_; }
  /// The sensor's pose at time t (clamped to [0, duration]): the track's
  /// pose turned by the look-arounds, the gait's sway and bob and the hand's
  /// shake, pitched down a few degrees as a hand holds it.
  [[nodiscard]] Pose sensor(double t) const;
  /// The walker's track at time t: the path's centre at the sensor's height,
  /// level, heading along the path (the street the world is built along).
  [[nodiscard]] Pose track(double t) const;

 private:
  /// Arc length walked by time t [m].
  [[nodiscard]] double walked(double t) const;
  /// The gait's step phase at time t [rad].
  [[nodiscard]] double phase(double t) const;
  /// Path position (x, y) and heading at arc length s.
  void path_at(double s, Eigen::Vector2d& xy, double& heading) const;
  /// World = the start's position and heading, z up.
  [[nodiscard]] Pose rebased(const Pose& raw) const { return origin_inverse_ * raw; }

  double duration_ = 60.0;
  double time_step_ = 0.005;              ///< [s] between samples of walked_ and phase_
  std::vector<double> walked_, phase_;    ///< arc length [m] and step phase [rad] per time sample
  double path_step_ = 0.02;               ///< [m] between path samples
  std::vector<Eigen::Vector2d> path_xy_;  ///< path positions per path sample
  std::vector<double> path_heading_;      ///< [rad] per path sample
  Pose origin_inverse_ = Pose::Identity();
};

}  // namespace saloam
