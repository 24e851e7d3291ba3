#include "saloam/odometry/deskew.hpp"

namespace saloam {

void deskew(FeatureCloud& cloud, const Vector6d& frame_motion, double frame_period, double pose_time_in_sweep) {
  if (frame_period <= 0.0) return;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double s = (static_cast<double>(cloud.sweep_time[i]) - pose_time_in_sweep) / frame_period;
    cloud.points[i] = se3_exp(s * frame_motion) * cloud.points[i];
  }
}

ScanFeatures deskewed(const ScanFeatures& scan, const Vector6d& frame_motion, double frame_period, double pose_time_in_sweep) {
  ScanFeatures out = scan;
  deskew(out.edges, frame_motion, frame_period, pose_time_in_sweep);
  deskew(out.planars, frame_motion, frame_period, pose_time_in_sweep);
  return out;
}

}  // namespace saloam
