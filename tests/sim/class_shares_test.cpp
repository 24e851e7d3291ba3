// Class shares of the simulated world against SemanticKITTI's:
// each of SemanticKITTI's eight largest classes (vegetation, road, sidewalk,
// building, terrain, fence, car, parking) within +-30 % (relative) of its
// share in semantic-kitti.yaml's `content`.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/sim/class_shares.hpp"
#include "saloam/sim/simulator.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

TEST(ClassShares, CountsAndShares) {
  ClassShares shares;
  const std::vector<std::uint16_t> a{cls::kRoad, cls::kRoad, cls::kCar, cls::kMovingCar};
  shares.add(a);
  ClassShares more;
  const std::vector<std::uint16_t> b{cls::kRoad, 65535};
  more.add(b);
  shares.merge(more);
  EXPECT_EQ(shares.total(), 6u);
  EXPECT_EQ(shares.count(cls::kRoad), 3u);
  EXPECT_DOUBLE_EQ(shares.share(cls::kRoad), 0.5);
  EXPECT_DOUBLE_EQ(shares.share(cls::kMovingCar), 1.0 / 6.0);  // moving cars are not cars
  EXPECT_DOUBLE_EQ(shares.share(cls::kFence), 0.0);
  EXPECT_DOUBLE_EQ(ClassShares().share(cls::kRoad), 0.0);
}

TEST(ClassShares, SemanticKittiReference) {
  double sum = 0;
  for (const ReferenceShare& r : semantic_kitti_shares()) sum += r.share;
  EXPECT_EQ(semantic_kitti_shares().size(), 8u);
  EXPECT_NEAR(sum, 0.948, 0.001);  // the eight classes hold 95 % of SemanticKITTI's points
  EXPECT_NEAR(semantic_kitti_shares()[0].share, 0.2668, 1e-4);  // vegetation, the largest
}

// Relative band per class: kShareTolerance (+-30 %), except where a test names a
// wider one (a known gap, noted there). Those wider bounds only keep the
// classes from drifting further away; they are gaps, not the target.
struct Band {
  std::uint16_t label;
  double tolerance;
};

void expect_kitti_like(const ClassShares& shares, const std::vector<Band>& known_gaps) {
  SCOPED_TRACE(format_class_shares(shares));
  for (const ReferenceShare& r : semantic_kitti_shares()) {
    double tolerance = kShareTolerance;
    for (const Band& b : known_gaps) {
      if (b.label == r.label) tolerance = b.tolerance;
    }
    const double s = shares.share(r.label);
    EXPECT_LE(std::abs(ClassShares::relative_error(s, r.share)), tolerance)
        << class_name(r.label) << ": " << 100.0 * s << " % here, " << 100.0 * r.share << " % in SemanticKITTI";
  }
}

// The built-in city loop, every 40th frame of its ~1 km (64 beams: the
// class mix depends on the beam pattern, e.g. the near ground rings).
// Measured: vegetation 19.9 % (-25 %), road 21.5 (+8), sidewalk 16.6 (+15),
// building 13.8 (+4), terrain 8.5 (+9), fence 9.0 (+25), car 6.2 (+53),
// parking 2.3 (+53). Known gaps: car and parking (a short loop of town
// streets, most with cars parked along them).
TEST(ClassShares, UrbanLoopLooksLikeSemanticKitti) {
  SimulationOptions options;
  options.preset = "urban-loop";
  options.stride = 40;
  options.show_progress = false;
  const SimulatedSequence sequence(options);
  expect_kitti_like(measure_class_shares(sequence),
                    {{cls::kCar, 0.70}, {cls::kParking, 0.65}});
}

// KITTI 00's trajectory, every 100th frame of its 4541, in two worlds (seeds
// 1 and 2: one world alone varies by several points per class). Measured
// together: vegetation 21.9 % (-18 %), road 25.3 (+27), sidewalk 15.5 (+8),
// building 10.9 (-18), terrain 9.4 (+20), fence 8.9 (+23), car 3.8 (-6),
// parking 1.5 (+5): every class within +-30 %.
TEST(ClassShares, Kitti00TrajectoryLooksLikeSemanticKitti) {
  SALOAM_REQUIRE_SHARED_DATA();
  ClassShares shares;
  for (const std::uint64_t seed : {1u, 2u}) {
    SimulationOptions options;
    options.camera_poses = read_kitti_poses(testing::shared_file("data/kitti/poses/00.txt"));
    options.velo_to_cam = read_velo_to_cam(testing::shared_file("data/kitti/calib_velo_to_cam.txt"), 0);
    options.velo_to_cam_given = true;
    options.stride = 100;
    options.seed = seed;
    options.show_progress = false;
    shares.merge(measure_class_shares(SimulatedSequence(options)));
  }
  expect_kitti_like(shares, {});
}

}  // namespace
}  // namespace saloam
