#pragma once
// Invariants of every pose a reader returns: finite, and a rotation (the
// readers re-orthonormalise what they accept).

#include "fuzz_support.hpp"
#include "saloam/core/types.hpp"

namespace saloam::fuzz {

inline void check_rigid(const Pose& T) {
  SALOAM_FUZZ_CHECK(T.matrix().allFinite());
  const Eigen::Matrix3d R = T.linear();
  SALOAM_FUZZ_CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-6);
  SALOAM_FUZZ_CHECK(R.determinant() > 0.0);
}

inline void check_trajectory(const Trajectory& trajectory) {
  SALOAM_FUZZ_CHECK(!trajectory.empty());
  SALOAM_FUZZ_CHECK(trajectory.timestamps.size() == trajectory.poses.size());
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    SALOAM_FUZZ_CHECK(std::isfinite(trajectory.timestamps[i]));
    if (i > 0) SALOAM_FUZZ_CHECK(trajectory.timestamps[i] > trajectory.timestamps[i - 1]);
    check_rigid(trajectory.poses[i]);
  }
}

}  // namespace saloam::fuzz
