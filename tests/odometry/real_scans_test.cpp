// Real KITTI data: six consecutive HDL-64E scans of sequence 00 (no labels).
// Reference: relative_poses_icp.txt (T_Li<-Li+1), see shared/data/kitti/README.md
// (the official GT is a constant-velocity fill for these frames).

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "saloam/core/lie.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/odometry/features.hpp"
#include "saloam/odometry/semantic_odometry.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

constexpr double kMaxTranslationError = 0.05;  // [m]
constexpr double kMaxRotationErrorDeg = 0.2;

std::vector<LabelledCloud> load_scans() {
  std::vector<LabelledCloud> scans;
  for (int i = 0; i < 6; ++i) {
    char name[48];  // room for any int, so that g++ -O1 sees no truncation
    std::snprintf(name, sizeof(name), "data/kitti/scans_00/%06d.bin", i);
    scans.push_back(read_scan(testing::shared_file(name)));
  }
  return scans;
}

OdometryConfig real_kitti_config() {
  OdometryConfig config;
  config.features.pose_time_in_sweep = 0.05;  // KITTI poses: LiDAR facing forward, mid-sweep
  return config;
}

struct Error {
  double translation;
  double rotation_deg;
};
Error relative_error(const Pose& estimate, const Pose& reference) {
  const Pose d = reference.inverse() * estimate;
  return {d.translation().norm(), rotation_angle(d) * 180.0 / M_PI};
}

// KITTI stores a scan ring by ring, each counter-clockwise from about
// azimuth 0, top ring first: 64 runs whose elevations fall monotonically.
TEST(RealKittiScans, StorageOrderGivesSixtyFourRings) {
  SALOAM_REQUIRE_SHARED_DATA();
  for (const auto& scan : load_scans()) {
    const auto rings = rings_from_point_order(scan, FeatureConfig{}, 64);
    ASSERT_EQ(rings.size(), 64u);
    double previous_elevation = 90.0;
    for (const auto& ring : rings) {
      ASSERT_GT(ring.size(), 500u);
      std::vector<double> elevation;
      for (const auto i : ring) {
        const auto& p = scan.points[i];
        elevation.push_back(std::atan2(p.z(), std::hypot(p.x(), p.y())) * 180.0 / M_PI);
      }
      std::nth_element(elevation.begin(), elevation.begin() + elevation.size() / 2, elevation.end());
      const double median = elevation[elevation.size() / 2];
      EXPECT_LT(median, previous_elevation + 0.6);  // the HDL-64E's lasers are not in exact order
      previous_elevation = median;
    }
  }
}

TEST(RealKittiScans, EachConsecutivePairMatchesIcpReference) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto scans = load_scans();
  const auto reference = read_kitti_poses(testing::shared_file("data/kitti/scans_00/relative_poses_icp.txt"));
  ASSERT_EQ(reference.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    SemanticOdometry odometry(real_kitti_config());
    odometry.register_frame(scans[i], 0.0);
    const Pose estimate = odometry.register_frame(scans[i + 1], 0.1);
    const Error e = relative_error(estimate, reference[i]);
    std::printf("pair %d->%d: %.1f cm, %.3f deg (motion %.3f m)\n", i, i + 1, 100 * e.translation, e.rotation_deg,
                estimate.translation().norm());
    EXPECT_LT(e.translation, kMaxTranslationError) << "pair " << i;
    EXPECT_LT(e.rotation_deg, kMaxRotationErrorDeg) << "pair " << i;
  }
}

TEST(RealKittiScans, OdometryOverSixScansMatchesIcpReference) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto scans = load_scans();
  const auto reference = read_kitti_poses(testing::shared_file("data/kitti/scans_00/relative_poses_icp.txt"));
  SemanticOdometry odometry(real_kitti_config());
  for (int i = 0; i < 6; ++i) odometry.register_frame(scans[i], 0.1 * i);
  const auto& poses = odometry.poses();
  ASSERT_EQ(poses.size(), 6u);
  for (int i = 0; i < 5; ++i) {
    const Error e = relative_error(poses[i].inverse() * poses[i + 1], reference[i]);
    std::printf("odometry %d->%d: %.1f cm, %.3f deg\n", i, i + 1, 100 * e.translation, e.rotation_deg);
    EXPECT_LT(e.translation, kMaxTranslationError) << "frame " << i;
    EXPECT_LT(e.rotation_deg, kMaxRotationErrorDeg) << "frame " << i;
  }
}

}  // namespace
}  // namespace saloam
