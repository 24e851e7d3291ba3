#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/odometry/features.hpp"

namespace saloam {
namespace {

TEST(RingAssignment, Hdl64BlocksHaveTheirOwnSpacing) {
  // Upper block: +2.0 .. -8.33 deg in 31 steps of ~1/3 deg.
  EXPECT_EQ(ring_from_elevation(2.0, BeamLayout::kHdl64), 0);
  EXPECT_EQ(ring_from_elevation(2.0 - 10.33 / 31.0, BeamLayout::kHdl64), 1);
  EXPECT_EQ(ring_from_elevation(-8.33, BeamLayout::kHdl64), 31);
  // Lower block: -8.83 .. -24.9 deg in 31 steps of ~1/2 deg.
  EXPECT_EQ(ring_from_elevation(-8.83, BeamLayout::kHdl64), 32);
  EXPECT_EQ(ring_from_elevation(-8.83 - 16.07 / 31.0, BeamLayout::kHdl64), 33);
  EXPECT_EQ(ring_from_elevation(-24.9, BeamLayout::kHdl64), 63);
  // Every beam of the layout maps to its own ring.
  for (int r = 0; r < 32; ++r) EXPECT_EQ(ring_from_elevation(2.0 - r * 10.33 / 31.0, BeamLayout::kHdl64), r);
  for (int r = 0; r < 32; ++r) EXPECT_EQ(ring_from_elevation(-8.83 - r * 16.07 / 31.0, BeamLayout::kHdl64), 32 + r);
  // Outside the field of view.
  EXPECT_EQ(ring_from_elevation(10.0, BeamLayout::kHdl64), -1);
  EXPECT_EQ(ring_from_elevation(-40.0, BeamLayout::kHdl64), -1);
}

TEST(RingAssignment, ThirtyTwoAndSixteenBeams) {
  for (int r = 0; r < 32; ++r) EXPECT_EQ(ring_from_elevation(10.67 - r * 4.0 / 3.0, BeamLayout::kHdl32), r);
  for (int r = 0; r < 16; ++r) EXPECT_EQ(ring_from_elevation(15.0 - 2.0 * r, BeamLayout::kVlp16), r);
  EXPECT_EQ(ring_count(BeamLayout::kHdl32), 32);
  EXPECT_EQ(ring_count(BeamLayout::kVlp16), 16);
}

std::vector<Eigen::Vector3f> synthetic_beams(const std::vector<double>& elevations_deg) {
  std::vector<Eigen::Vector3f> pts;
  for (double e : elevations_deg) {
    for (int a = 0; a < 360; a += 2) {
      const double el = e * M_PI / 180.0, az = a * M_PI / 180.0;
      pts.emplace_back(static_cast<float>(10 * std::cos(el) * std::cos(az)),
                       static_cast<float>(10 * std::cos(el) * std::sin(az)), static_cast<float>(10 * std::sin(el)));
    }
  }
  return pts;
}

TEST(RingAssignment, DetectsLayoutFromElevationRange) {
  std::vector<double> e64, e32, e16;
  for (int r = 0; r < 32; ++r) e64.push_back(2.0 - r * 10.33 / 31.0);
  for (int r = 0; r < 32; ++r) e64.push_back(-8.83 - r * 16.07 / 31.0);
  for (int r = 0; r < 32; ++r) e32.push_back(10.67 - r * 4.0 / 3.0);
  for (int r = 0; r < 16; ++r) e16.push_back(15.0 - 2.0 * r);
  EXPECT_EQ(detect_beam_layout(synthetic_beams(e64), 0), BeamLayout::kHdl64);
  EXPECT_EQ(detect_beam_layout(synthetic_beams(e32), 0), BeamLayout::kHdl32);
  EXPECT_EQ(detect_beam_layout(synthetic_beams(e16), 0), BeamLayout::kVlp16);
  EXPECT_EQ(detect_beam_layout(synthetic_beams(e16), 64), BeamLayout::kHdl64);  // explicit wins
}

TEST(SweepTime, ClockwiseFromBehindReachesFrontAtMidSweep) {
  FeatureConfig config;  // start 180 deg, clockwise, 0.1 s
  EXPECT_NEAR(sweep_time_from_azimuth(M_PI - 1e-9, config), 0.0, 1e-6);
  EXPECT_NEAR(sweep_time_from_azimuth(M_PI / 2, config), 0.025, 1e-9);  // left side a quarter in
  EXPECT_NEAR(sweep_time_from_azimuth(0.0, config), 0.05, 1e-9);        // front at mid-sweep
  EXPECT_NEAR(sweep_time_from_azimuth(-M_PI / 2, config), 0.075, 1e-9);
  config.sweep_clockwise = false;
  EXPECT_NEAR(sweep_time_from_azimuth(-M_PI / 2, config), 0.025, 1e-9);
}

// A ring sampled along a polyline: a straight wall, then a 90 deg corner.
std::vector<Eigen::Vector3d> corner_ring() {
  std::vector<Eigen::Vector3d> ring;
  for (int i = 0; i <= 40; ++i) ring.emplace_back(10.0, -2.0 + 0.1 * i, 0.0);  // wall x = 10
  for (int i = 1; i <= 40; ++i) ring.emplace_back(10.0 - 0.1 * i, 2.0, 0.0);   // wall y = 2
  return ring;
}

TEST(Roughness, ZeroOnStraightLineLargeAtCorner) {
  const auto ring = corner_ring();
  const auto c = ring_roughness(ring, 5);
  ASSERT_EQ(c.size(), ring.size());
  EXPECT_TRUE(std::isinf(c[0]));  // no full window
  EXPECT_TRUE(std::isinf(c[ring.size() - 1]));
  EXPECT_NEAR(c[20], 0.0, 1e-12);  // middle of the first wall
  EXPECT_NEAR(c[60], 0.0, 1e-12);
  // At the corner: sum over 5 each side of (X_j - X_i) = -(0.1+..+0.5) * (e_y) ... both sides:
  // left side contributes (0, -1.5, 0), right side (-1.5, 0, 0): |.|^2 = 4.5.
  EXPECT_NEAR(c[40], 4.5, 1e-9);
  int argmax = 0;
  for (int i = 5; i < static_cast<int>(c.size()) - 5; ++i) {
    if (c[i] > c[argmax] || std::isinf(c[argmax])) argmax = i;
  }
  EXPECT_EQ(argmax, 40);
}

TEST(UnreliablePoints, RangeLimitsOcclusionAndGrazingBeams) {
  std::vector<Eigen::Vector3d> ring;
  for (int i = 0; i < 20; ++i) ring.emplace_back(5.0, -1.0 + 0.05 * i, 0.0);   // near object
  for (int i = 0; i < 20; ++i) ring.emplace_back(20.0, 0.0 + 0.2 * i, 0.0);    // far wall behind it
  const auto bad = unreliable_points(ring, 5, 2.5, 100.0);
  // The far points right after the jump are occluded (hidden surface continues behind the object).
  for (int k = 20; k < 25; ++k) EXPECT_TRUE(bad[k]) << k;
  EXPECT_FALSE(bad[10]);
  EXPECT_FALSE(bad[32]);
  // Near the sensor and far away.
  std::vector<Eigen::Vector3d> r2{{1.0, 0, 0}, {1.0, 0.01, 0}, {150, 0, 0}};
  const auto bad2 = unreliable_points(r2, 1, 2.5, 120.0);
  EXPECT_TRUE(bad2[0]);
  EXPECT_TRUE(bad2[2]);
  // A grazing surface: consecutive returns far apart along the beam direction.
  std::vector<Eigen::Vector3d> graze;
  for (int i = 0; i < 30; ++i) graze.emplace_back(10.0 + 0.6 * i, 0.02 * i, 0.0);
  const auto bad3 = unreliable_points(graze, 5, 1.0, 100.0);
  EXPECT_TRUE(bad3[15]);
}

TEST(FeatureSelection, EdgesAtCornerPlanarsOnWallsWithLimits) {
  const auto ring = corner_ring();
  const auto c = ring_roughness(ring, 5);
  const PointMask unreliable(ring.size(), 0);
  FeatureConfig config;
  config.num_sectors = 1;
  config.edges_per_sector = 2;
  config.planars_per_sector = 4;
  const auto sel = select_ring_features(ring, c, unreliable, config);
  ASSERT_FALSE(sel.edges.empty());
  EXPECT_LE(sel.edges.size(), 2u);
  EXPECT_EQ(sel.edges.front(), 40);  // sharpest first
  EXPECT_EQ(sel.planars.size(), 4u);
  for (int i : sel.planars) {
    EXPECT_LT(c[i], config.alpha);
    EXPECT_GT(std::abs(i - 40), 5);  // not next to the corner
  }
  // Non-maximum suppression: selected planars are not ring neighbours of each other.
  for (std::size_t a = 0; a < sel.planars.size(); ++a) {
    for (std::size_t b = a + 1; b < sel.planars.size(); ++b) EXPECT_GT(std::abs(sel.planars[a] - sel.planars[b]), 5);
  }
  // Points marked not-edge (rough ground) give no edges but may be planar.
  const auto planar_only = select_ring_features(ring, c, unreliable, config, PointMask(ring.size(), 1));
  EXPECT_TRUE(planar_only.edges.empty());
  EXPECT_EQ(planar_only.planars.size(), 4u);
  // Threshold: with alpha above every roughness there are no edges.
  config.alpha = 10.0;
  EXPECT_TRUE(select_ring_features(ring, c, unreliable, config).edges.empty());
}

TEST(FeatureSelection, PerSectorLimits) {
  std::vector<Eigen::Vector3d> ring;
  for (int i = 0; i < 600; ++i) ring.emplace_back(10.0, -30.0 + 0.1 * i, 0.0);
  const auto c = ring_roughness(ring, 5);
  FeatureConfig config;  // N_r = 6, N_p = 50
  const auto sel = select_ring_features(ring, c, PointMask(ring.size(), 0), config);
  EXPECT_TRUE(sel.edges.empty());
  // ~98 points per sector, one in 6 after suppression => ~16 per sector, never above N_p.
  EXPECT_GT(sel.planars.size(), 6u * 10);
  config.planars_per_sector = 3;
  EXPECT_EQ(select_ring_features(ring, c, PointMask(ring.size(), 0), config).planars.size(), 18u);
}

TEST(SemanticClasses, DynamicAndUnlabeledAreNotUsed) {
  EXPECT_LT(odometry_class(cls::kUnlabeled), 0);
  EXPECT_LT(odometry_class(cls::kOutlier), 0);
  EXPECT_LT(odometry_class(cls::kMovingCar), 0);
  EXPECT_LT(odometry_class(cls::kPerson), 0);
  EXPECT_LT(odometry_class(cls::kBicyclist), 0);
  EXPECT_GT(odometry_class(cls::kRoad), 0);
  EXPECT_EQ(odometry_class(cls::kLaneMarking), odometry_class(cls::kRoad));
  EXPECT_GT(odometry_class(cls::kCar), 0);  // parked cars are static
  EXPECT_NE(odometry_class(cls::kPole), odometry_class(cls::kBuilding));
}

TEST(SemanticClasses, GroupsMergeConfusableClassesWithSharedGeometry) {
  auto c = [](std::uint16_t raw) { return static_cast<ClassIndex>(odometry_class(raw)); };
  EXPECT_EQ(class_group(c(cls::kSidewalk)), c(cls::kRoad));
  EXPECT_EQ(class_group(c(cls::kParking)), c(cls::kRoad));
  EXPECT_EQ(class_group(c(cls::kTerrain)), c(cls::kRoad));
  EXPECT_EQ(class_group(c(cls::kFence)), c(cls::kBuilding));
  EXPECT_EQ(class_group(c(cls::kTrunk)), c(cls::kPole));
  EXPECT_EQ(class_group(c(cls::kTrafficSign)), c(cls::kPole));
  EXPECT_EQ(class_group(c(cls::kTruck)), c(cls::kCar));
  EXPECT_EQ(class_group(c(cls::kVegetation)), c(cls::kVegetation));
  EXPECT_NE(class_group(c(cls::kBuilding)), class_group(c(cls::kRoad)));
  EXPECT_NE(class_group(c(cls::kPole)), class_group(c(cls::kVegetation)));
  EXPECT_EQ(class_group(0), 0);
}

// A 16-ring scan stored ring by ring: every ring starts at `seam_deg` and
// turns in the given sense, with a gap (no returns) in every third ring.
LabelledCloud ring_by_ring_scan(double seam_deg, bool clockwise) {
  LabelledCloud cloud;
  for (int r = 0; r < 16; ++r) {
    const double el = (15.0 - 2.0 * r) * M_PI / 180.0;
    for (int a = 0; a < 1800; ++a) {
      if (r % 3 == 0 && a > 300 && a < 500) continue;
      const double turned = 2 * M_PI * (a + 0.5) / 1800.0;
      const double az = seam_deg * M_PI / 180.0 + (clockwise ? -turned : turned);
      const double range = 12.0 + 3.0 * std::sin(5 * az);
      const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      cloud.push_back((range * d).cast<float>(), 0.5f, static_cast<std::uint16_t>(r));  // label = ring, for the test
    }
  }
  return cloud;
}

void expect_rings_of(const LabelledCloud& cloud, const std::vector<std::vector<std::uint32_t>>& rings) {
  ASSERT_EQ(rings.size(), 16u);
  for (std::size_t r = 0; r < rings.size(); ++r) {
    EXPECT_EQ(rings[r].size(), r % 3 == 0 ? 1601u : 1800u) << "ring " << r;
    for (const auto i : rings[r]) ASSERT_EQ(cloud.label[i], r) << "point " << i;
  }
}

TEST(RingsFromStorage, SweepOrderOfTheSimulator) {
  FeatureConfig config;  // sweep from azimuth 180 deg, clockwise
  const auto cloud = ring_by_ring_scan(180.0, true);
  expect_rings_of(cloud, rings_from_point_order(cloud, config, 16));
}

TEST(RingsFromStorage, KittiOrderCounterClockwiseFromTheFront) {
  // Real KITTI stores each ring counter-clockwise from azimuth 0, which the
  // sweep model (clockwise from 180 deg) does not describe.
  FeatureConfig config;
  for (const double seam : {0.0, 0.3, -40.0}) {
    SCOPED_TRACE(seam);
    const auto cloud = ring_by_ring_scan(seam, false);
    expect_rings_of(cloud, rings_from_point_order(cloud, config, 16));
  }
  const auto clockwise_from_front = ring_by_ring_scan(0.0, true);
  expect_rings_of(clockwise_from_front, rings_from_point_order(clockwise_from_front, config, 16));
}

TEST(RingsFromStorage, ShuffledPointsAreNotRings) {
  FeatureConfig config;
  auto cloud = ring_by_ring_scan(0.0, false);
  std::mt19937 rng(7);
  std::shuffle(cloud.points.begin(), cloud.points.end(), rng);
  EXPECT_TRUE(rings_from_point_order(cloud, config, 16).empty());
  EXPECT_TRUE(rings_from_point_order(cloud, config, 0).empty());
}

// A synthetic 64-beam scan of a box-shaped room with a pole, labelled.
LabelledCloud room_scan(bool labelled) {
  LabelledCloud cloud;
  cloud.has_labels = labelled;
  for (int r = 0; r < 64; ++r) {
    const double el = (r < 32 ? 2.0 - r * 10.33 / 31.0 : -8.83 - (r - 32) * 16.07 / 31.0) * M_PI / 180.0;
    for (int a = 0; a < 2000; ++a) {
      const double az = -M_PI + 2 * M_PI * a / 2000.0;
      const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      // Walls at |x| = 15, |y| = 10, ground at z = -1.7.
      double t = 1e9;
      std::uint16_t label = cls::kBuilding;
      for (double wx : {15.0, -15.0}) if (d.x() * wx > 0) t = std::min(t, wx / d.x());
      for (double wy : {10.0, -10.0}) if (d.y() * wy > 0) t = std::min(t, wy / d.y());
      if (d.z() < 0 && -1.7 / d.z() < t) {
        t = -1.7 / d.z();
        label = cls::kRoad;
      }
      // A moving car in front: a box x in [5, 7], y in [-1, 1].
      if (d.x() > 0 && std::abs(5.0 * d.y() / d.x()) < 1.0 && 5.0 / d.x() < t && (5.0 / d.x()) * d.z() > -1.7) {
        t = 5.0 / d.x();
        label = cls::kMovingCar;
      }
      cloud.push_back((t * d).cast<float>(), 0.5f, labelled ? label : 0);
    }
  }
  return cloud;
}

TEST(ExtractFeatures, LabelledScanDropsDynamicClassesUnlabeledKeepsOneClass) {
  FeatureConfig config;
  const auto labelled = extract_features(room_scan(true), config, true);
  ASSERT_GT(labelled.planars.size(), 500u);
  ASSERT_GT(labelled.edges.size(), 10u);
  const int car = odometry_class(cls::kCar);
  bool has_road = false, has_building = false;
  for (auto c : labelled.planars.classes) {
    EXPECT_NE(c, car);
    EXPECT_NE(c, 0);
    has_road |= c == odometry_class(cls::kRoad);
    has_building |= c == odometry_class(cls::kBuilding);
  }
  EXPECT_TRUE(has_road);
  EXPECT_TRUE(has_building);
  // No feature on the moving car (x in [5, 7] in front).
  for (const auto& p : labelled.planars.points) {
    EXPECT_FALSE(p.x() > 4.9 && p.x() < 5.1 && std::abs(p.y()) < 1.0 && p.z() > -1.65);
  }

  // ground_edge_alpha: with .inf the road gives planars only (LeGO-LOAM
  // style) and the walls' corners remain edges; at alpha the road gives edges too.
  auto road_edges = [](const ScanFeatures& f) {
    return std::count(f.edges.classes.begin(), f.edges.classes.end(), odometry_class(cls::kRoad));
  };
  FeatureConfig ground_planar_only = config;
  ground_planar_only.ground_edge_alpha = std::numeric_limits<double>::infinity();
  const auto planar_ground = extract_features(room_scan(true), ground_planar_only, true);
  EXPECT_EQ(road_edges(planar_ground), 0);
  EXPECT_GT(planar_ground.edges.size(), 10u);
  FeatureConfig ground_like_others = config;
  ground_like_others.ground_edge_alpha = config.alpha;
  EXPECT_GT(road_edges(extract_features(room_scan(true), ground_like_others, true)), 0);

  const auto unlabelled = extract_features(room_scan(false), config, false);
  ASSERT_GT(unlabelled.planars.size(), 500u);
  for (auto c : unlabelled.planars.classes) EXPECT_EQ(c, 0);
  // Sweep times are within one revolution.
  for (float t : unlabelled.planars.sweep_time) {
    EXPECT_GE(t, 0.0f);
    EXPECT_LT(t, 0.1f + 1e-6f);
  }
}

/// One ring of a sensor at the origin crossing a vertical cylinder (centre
/// `centre`, radius r) in front of a wall `wall` m away, the azimuth step
/// `step` [rad] starting at `phase` steps, ranges with Gaussian noise.
struct CylinderRing {
  std::vector<Eigen::Vector3d> points;
  int on_cylinder = -1;  ///< index of a return on the cylinder
};
CylinderRing cylinder_ring(const Eigen::Vector2d& centre, double r, double wall, double step, double phase,
                           double noise, std::mt19937& rng) {
  std::normal_distribution<double> range_noise(0.0, noise);
  CylinderRing ring;
  const double azimuth = std::atan2(centre.y(), centre.x());
  for (int i = -60; i <= 60; ++i) {
    const double a = azimuth + (i + phase) * step;
    const Eigen::Vector2d u(std::cos(a), std::sin(a));
    // Ray-circle intersection: t^2 - 2 t (u . c) + |c|^2 - r^2 = 0.
    const double b = u.dot(centre), disc = b * b - centre.squaredNorm() + r * r;
    const bool hit = disc >= 0.0;
    const double t = (hit ? b - std::sqrt(disc) : wall) + range_noise(rng);
    if (hit && ring.on_cylinder < 0) ring.on_cylinder = static_cast<int>(ring.points.size());
    ring.points.emplace_back(t * u.x(), t * u.y(), -1.0);
  }
  return ring;
}

TEST(ThinObjectAxis, FindsThePoleAxisFromAnyViewpointWithoutBias) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> phase(0.0, 1.0);
  constexpr double kStep = 2.0 * M_PI / 2083;  // the HDL-64E's azimuth step
  for (const double r : {0.05, 0.12, 0.25}) {
    for (const double distance : {5.0, 12.0, 25.0}) {
      // The mean error over many crossings (random phase of the beams,
      // 2 cm range noise) is the bias (measured: within 2 mm); the
      // crossing's first return lies 0.28 r to r in front of the axis.
      Eigen::Vector2d error_sum = Eigen::Vector2d::Zero();
      double return_error_sum = 0.0;  // of the crossing's first return, along the ray
      int crossings = 0;
      for (int trial = 0; trial < 400; ++trial) {
        const double bearing = 2.0 * M_PI * phase(rng);
        const Eigen::Vector2d centre = distance * Eigen::Vector2d(std::cos(bearing), std::sin(bearing));
        const CylinderRing ring = cylinder_ring(centre, r, distance + 8.0, kStep, phase(rng), 0.02, rng);
        if (ring.on_cylinder < 0) continue;
        const auto axis = thin_object_axis(ring.points, ring.on_cylinder, 0.5);
        ASSERT_TRUE(axis) << r << " " << distance;
        EXPECT_NEAR(axis->point.z(), -1.0, 0.05);
        const Eigen::Vector2d ray = centre.normalized();
        const Eigen::Vector2d e = axis->point.head<2>() - centre;
        error_sum += Eigen::Vector2d(e.dot(ray), e.dot(Eigen::Vector2d(-ray.y(), ray.x())));
        return_error_sum += (ring.points[static_cast<std::size_t>(ring.on_cylinder)].head<2>() - centre).dot(ray);
        ++crossings;
      }
      ASSERT_GT(crossings, 300);
      const Eigen::Vector2d bias = error_sum / crossings;  // along the ray, across it
      EXPECT_LT(std::abs(bias.x()), 0.006) << "radius " << r << " at " << distance << " m";
      EXPECT_LT(std::abs(bias.y()), 0.003) << "radius " << r << " at " << distance << " m";
      EXPECT_LT(return_error_sum / crossings, -0.2 * r) << "radius " << r << " at " << distance << " m";
    }
  }
}

TEST(ThinObjectAxis, AWideRunIsNoThinObject) {
  std::mt19937 rng(2);
  // A 1 m "trunk" in front of a wall 0.1 m behind it: the run merges with the wall.
  const CylinderRing wide = cylinder_ring({10.0, 0.0}, 1.0, 20.0, 2.0 * M_PI / 2083, 0.3, 0.0, rng);
  EXPECT_FALSE(thin_object_axis(wide.points, wide.on_cylinder, 0.5));
  const CylinderRing merged = cylinder_ring({10.0, 0.0}, 0.1, 10.05, 2.0 * M_PI / 2083, 0.3, 0.0, rng);
  EXPECT_FALSE(thin_object_axis(merged.points, merged.on_cylinder, 0.5));
  // A pole half hidden behind a nearer one: the crossing's end is cut.
  CylinderRing hidden = cylinder_ring({10.0, 0.0}, 0.1, 20.0, 2.0 * M_PI / 2083, 0.3, 0.0, rng);
  int last = hidden.on_cylinder;
  while (hidden.points[static_cast<std::size_t>(last) + 1].norm() < 15.0) ++last;
  for (std::size_t i = static_cast<std::size_t>(last) - 1; i < hidden.points.size() && hidden.points[i].norm() > 5.0; ++i) {
    hidden.points[i] *= 5.0 / hidden.points[i].norm();  // from the middle on, a nearer object 5 m away
  }
  EXPECT_FALSE(thin_object_axis(hidden.points, hidden.on_cylinder, 0.5));
  const CylinderRing thin = cylinder_ring({10.0, 0.0}, 0.1, 20.0, 2.0 * M_PI / 2083, 0.3, 0.0, rng);
  const auto axis = thin_object_axis(thin.points, thin.on_cylinder, 0.5);
  ASSERT_TRUE(axis);
  EXPECT_NEAR(axis->radius, 0.1, 0.03);
  EXPECT_NEAR(axis->point.x(), 10.0, 0.02);
  EXPECT_NEAR(axis->point.y(), 0.0, 0.02);
  EXPECT_TRUE(is_thin_round(cls::kPole));
  EXPECT_TRUE(is_thin_round(cls::kTrunk));
  EXPECT_FALSE(is_thin_round(cls::kTrafficSign));
}

}  // namespace
}  // namespace saloam
