#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "saloam/core/lie.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/odometry/local_map.hpp"
#include "saloam/odometry/registration.hpp"
#include "saloam/odometry/residuals.hpp"

namespace saloam {
namespace {

TEST(LineFit, RecoversDirectionAndRejectsBlobs) {
  std::vector<Eigen::Vector3d> pts;
  const Eigen::Vector3d dir = Eigen::Vector3d(1, 2, 3).normalized();
  for (int i = 0; i < 5; ++i) pts.push_back(Eigen::Vector3d(1, 1, 1) + 0.2 * i * dir + Eigen::Vector3d(0.001 * (i % 2), 0, 0));
  const auto line = fit_line(pts);
  ASSERT_TRUE(line);
  EXPECT_NEAR(std::abs(line->direction.dot(dir)), 1.0, 1e-4);
  EXPECT_LT(((line->point - Eigen::Vector3d(1, 1, 1)).cross(dir)).norm(), 1e-3);
  // A planar blob is not line-like.
  std::vector<Eigen::Vector3d> blob{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.5, 0}};
  EXPECT_FALSE(fit_line(blob));
}

TEST(PlaneFit, RecoversNormalAndRejectsNonPlanar) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.1, -0.2, 1.0).normalized();
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 5; ++i) pts.push_back(Eigen::Vector3d(3, 4, 5) + std::cos(i) * u + std::sin(2.0 * i) * v);
  const auto plane = fit_plane(pts);
  ASSERT_TRUE(plane);
  EXPECT_NEAR(std::abs(plane->normal.dot(n)), 1.0, 1e-9);
  EXPECT_NEAR(plane->normal.dot(plane->point - Eigen::Vector3d(3, 4, 5)), 0.0, 1e-9);
  pts[2] += 0.5 * n;  // one point far off the plane
  EXPECT_FALSE(fit_plane(pts, 0.2));
  std::vector<Eigen::Vector3d> collinear{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}};
  EXPECT_FALSE(fit_plane(collinear));
}

TEST(PlaneConstraint, GroundNeedsVerticalNormalBuildingHorizontal) {
  EXPECT_EQ(plane_orientation(cls::kRoad), PlaneOrientation::kHorizontal);
  EXPECT_EQ(plane_orientation(cls::kSidewalk), PlaneOrientation::kHorizontal);
  EXPECT_EQ(plane_orientation(cls::kParking), PlaneOrientation::kHorizontal);
  EXPECT_EQ(plane_orientation(cls::kTerrain), PlaneOrientation::kHorizontal);
  EXPECT_EQ(plane_orientation(cls::kOtherGround), PlaneOrientation::kHorizontal);
  EXPECT_EQ(plane_orientation(cls::kBuilding), PlaneOrientation::kVertical);
  EXPECT_EQ(plane_orientation(cls::kFence), PlaneOrientation::kVertical);
  EXPECT_EQ(plane_orientation(cls::kVegetation), PlaneOrientation::kAny);
  const double sigma = 0.05;
  const Eigen::Vector3d up(0, 0, 1), wall(1, 0, 0);
  const Eigen::Vector3d tilted20 = Eigen::AngleAxisd(20 * M_PI / 180, Eigen::Vector3d::UnitX()) * up;
  const Eigen::Vector3d tilted10 = Eigen::AngleAxisd(10 * M_PI / 180, Eigen::Vector3d::UnitX()) * up;
  EXPECT_TRUE(plane_satisfies_constraint(up, PlaneOrientation::kHorizontal, sigma));
  EXPECT_TRUE(plane_satisfies_constraint(-up, PlaneOrientation::kHorizontal, sigma));
  EXPECT_TRUE(plane_satisfies_constraint(tilted10, PlaneOrientation::kHorizontal, sigma));  // cos 10 = 0.985
  EXPECT_FALSE(plane_satisfies_constraint(tilted20, PlaneOrientation::kHorizontal, sigma));  // cos 20 = 0.94
  EXPECT_FALSE(plane_satisfies_constraint(wall, PlaneOrientation::kHorizontal, sigma));
  EXPECT_TRUE(plane_satisfies_constraint(wall, PlaneOrientation::kVertical, sigma));
  EXPECT_FALSE(plane_satisfies_constraint(up, PlaneOrientation::kVertical, sigma));
  EXPECT_FALSE(plane_satisfies_constraint(Eigen::Vector3d(1, 0, 0.1).normalized(), PlaneOrientation::kVertical, sigma));
  EXPECT_TRUE(plane_satisfies_constraint(Eigen::Vector3d(1, 1, 1).normalized(), PlaneOrientation::kAny, sigma));
}

Pose random_pose(std::mt19937& rng, double t_scale, double r_scale) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vector6d xi;
  for (int i = 0; i < 6; ++i) xi(i) = n(rng) * (i < 3 ? t_scale : r_scale);
  return se3_exp(xi);
}

TEST(ResidualJacobians, MatchNumericDifferentiation) {
  std::mt19937 rng(7);
  const double h = 1e-6;
  for (int trial = 0; trial < 20; ++trial) {
    const Pose T = random_pose(rng, 2.0, 0.5);
    const Eigen::Vector3d p = Eigen::Vector3d::Random() * 10.0;
    const Plane plane{Eigen::Vector3d::Random(), Eigen::Vector3d::Random().normalized()};
    const Line line{Eigen::Vector3d::Random(), Eigen::Vector3d::Random().normalized()};
    Eigen::Matrix<double, 1, 6> Jp;
    Eigen::Matrix<double, 3, 6> Jl;
    point_to_plane_residual(T, p, plane, &Jp);
    point_to_line_residual(T, p, line, &Jl);
    for (int k = 0; k < 6; ++k) {
      Vector6d d = Vector6d::Zero();
      d(k) = h;
      const Pose Tp = T * se3_exp(d), Tm = T * se3_exp(-d);  // right perturbation
      const double num_p = (point_to_plane_residual(Tp, p, plane) - point_to_plane_residual(Tm, p, plane)) / (2 * h);
      const Eigen::Vector3d num_l = (point_to_line_residual(Tp, p, line) - point_to_line_residual(Tm, p, line)) / (2 * h);
      EXPECT_NEAR(Jp(0, k), num_p, 1e-5 * (1 + std::abs(num_p)));
      EXPECT_LT((Jl.col(k) - num_l).norm(), 1e-5 * (1 + num_l.norm()));
    }
  }
}

TEST(ResidualJacobians, UpdateStaysOnTheManifold) {
  Pose T = Pose::Identity();
  Vector6d d;
  d << 0.1, -0.2, 0.3, 0.01, 0.02, -0.03;
  for (int i = 0; i < 1000; ++i) T = apply_update(d, T);
  EXPECT_LT((T.linear().transpose() * T.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(T.linear().determinant(), 1.0, 1e-12);
}

// A structured scene as features: ground, walls, poles, with classes.
ScanFeatures scene(std::mt19937& rng) {
  ScanFeatures f;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto road = static_cast<ClassIndex>(to_learning_class(cls::kRoad));
  const auto building = static_cast<ClassIndex>(to_learning_class(cls::kBuilding));
  const auto pole = static_cast<ClassIndex>(to_learning_class(cls::kPole));
  for (int i = 0; i < 1500; ++i) f.planars.push_back({20 * u(rng), 20 * u(rng), -1.7}, road, 0.0f);
  for (int i = 0; i < 800; ++i) f.planars.push_back({12.0, 15 * u(rng), 3 * u(rng) + 1}, building, 0.0f);
  for (int i = 0; i < 800; ++i) f.planars.push_back({15 * u(rng), -9.0, 3 * u(rng) + 1}, building, 0.0f);
  for (int i = 0; i < 800; ++i) f.planars.push_back({15 * u(rng), 14.0, 3 * u(rng) + 1}, building, 0.0f);
  for (const auto& [x, y] : {std::pair{5.0, 3.0}, std::pair{-4.0, 6.0}, std::pair{8.0, -5.0}, std::pair{-7.0, -3.0}}) {
    for (int i = 0; i < 60; ++i) f.edges.push_back({x, y, -1.7 + 0.08 * i}, pole, 0.0f);
  }
  return f;
}

// The features as a sensor at `sensor` (T_world<-sensor) measures them.
ScanFeatures seen_from(const ScanFeatures& world, const Pose& sensor) {
  ScanFeatures scan = world;
  for (auto& p : scan.edges.points) p = sensor.inverse() * p;
  for (auto& p : scan.planars.points) p = sensor.inverse() * p;
  return scan;
}

// A local map holding one frame of world features, with the default config.
SemanticLocalMap map_of(const FeatureCloud& edges, const FeatureCloud& planars) {
  const OdometryConfig config;
  SemanticLocalMap map(config.local_map_frames, class_voxel_sizes(config), config.max_correspondence_distance);
  map.add_frame(edges, planars);
  return map;
}

TEST(Registration, RecoversKnownTransformOfItself) {
  std::mt19937 rng(3);
  const ScanFeatures f = scene(rng);
  OdometryConfig config;
  const SemanticLocalMap map = map_of(f.edges, f.planars);
  Vector6d xi;
  xi << 0.4, -0.3, 0.05, 0.01, -0.01, 0.05;  // 0.5 m, ~3 deg
  const Pose truth = se3_exp(xi);
  // The scan is the scene seen from pose `truth`: p_scan = truth^-1 p_world.
  const ScanFeatures scan = seen_from(f, truth);
  for (bool semantics : {true, false}) {
    config.use_semantics = semantics;
    const auto settings = RegistrationSettings::from_config(config);
    const auto result = register_scan(scan.edges, scan.planars, map, Pose::Identity(), settings);
    ASSERT_TRUE(result.ok);
    const Pose err = truth.inverse() * result.pose;
    // Not exact: neighbourhoods at wall/wall and wall/road junctions give
    // slightly bent "planes" (fewer with per-class matching).
    EXPECT_LT(err.translation().norm(), semantics ? 1e-3 : 5e-3) << "semantics " << semantics;
    EXPECT_LT(rotation_angle(err), 5e-4) << "semantics " << semantics;
    EXPECT_GT(result.edge_matches, 100);
    EXPECT_GT(result.planar_matches, 2000);
  }
}

TEST(Registration, ConvergesAsWellFarFromTheOrigin) {
  // Regression: with the pose perturbed about the world origin, a scene a few
  // hundred metres away coupled rotation and translation through the lever
  // arm, Gauss-Newton ran out of iterations and stopped short of a 3 deg
  // rotation (lost track in sharp turns late in a sequence).
  std::mt19937 rng(5);
  const ScanFeatures local = scene(rng);
  OdometryConfig config;
  const auto settings = RegistrationSettings::from_config(config);
  Vector6d xi;
  xi << 0.3, 0.1, 0.02, 0.004, -0.004, 0.055;  // 0.3 m, ~3.2 deg (mostly yaw)
  const Pose motion = se3_exp(xi);
  for (const double distance : {0.0, 400.0}) {
    Pose place = Pose::Identity();
    place.linear() = Eigen::AngleAxisd(2.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    place.translation() = Eigen::Vector3d(0.8, -0.6, 0.02) * distance;
    ScanFeatures world = local;
    for (auto& p : world.edges.points) p = place * p;
    for (auto& p : world.planars.points) p = place * p;
    const SemanticLocalMap map = map_of(world.edges, world.planars);
    // The sensor sits at place * motion; the registration starts at `place`.
    const Pose truth = place * motion;
    const ScanFeatures scan = seen_from(world, truth);
    const auto result = register_scan(scan.edges, scan.planars, map, place, settings);
    ASSERT_TRUE(result.ok) << "distance " << distance;
    const Pose err = truth.inverse() * result.pose;
    EXPECT_LT(err.translation().norm(), 1e-3) << "distance " << distance;
    EXPECT_LT(rotation_angle(err), 5e-4) << "distance " << distance;
    EXPECT_LT(result.iterations, settings.max_iterations * settings.outer_iterations)
        << "ran out of iterations at distance " << distance;
  }
}

// A corridor: a floor and two walls along x, nothing across. Every residual
// is blind to a shift along x.
ScanFeatures corridor(std::mt19937& rng) {
  ScanFeatures f;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 1500; ++i) f.planars.push_back({30 * u(rng), 4 * u(rng), -1.7}, 0, 0.0f);
  for (int i = 0; i < 1000; ++i) f.planars.push_back({30 * u(rng), -4.0, 2 * u(rng) + 1}, 0, 0.0f);
  for (int i = 0; i < 1000; ++i) f.planars.push_back({30 * u(rng), 4.0, 2 * u(rng) + 1}, 0, 0.0f);
  return f;
}

TEST(Registration, DegenerateDirectionKeepsTheInitialGuess) {
  std::mt19937 rng(13);
  const ScanFeatures world = corridor(rng);
  OdometryConfig config;
  config.use_semantics = false;
  const SemanticLocalMap map = map_of(world.edges, world.planars);
  // The sensor moved 0.7 m along the corridor, 0.1 m across and turned 2 deg;
  // the prediction (initial guess) says 0.6 m along, nothing else.
  Vector6d xi;
  xi << 0.7, 0.1, 0.02, 0.0, 0.0, 0.035;
  const Pose truth = se3_exp(xi);
  Pose guess = Pose::Identity();
  guess.translation().x() = 0.6;
  const ScanFeatures scan = seen_from(world, truth);
  const auto settings = RegistrationSettings::from_config(config);
  ASSERT_GT(settings.degeneracy_eigenvalue, 0.0);
  const auto result = register_scan(scan.edges, scan.planars, map, guess, settings);
  ASSERT_TRUE(result.ok);
  // Along x nothing constrains the pose; the roll, from points at most 4 m
  // off the axis, is weak at the features' RMS range too (about 17 m).
  EXPECT_GE(result.degenerate_directions, 1);
  EXPECT_LE(result.degenerate_directions, 2);
  EXPECT_TRUE(result.degenerate());
  EXPECT_LT(result.smallest_eigenvalue, settings.degeneracy_eigenvalue);
  // Across, up and in yaw the scene decides: the truth. Along the corridor
  // the guess stays (the estimate moves only across the corridor's axis,
  // world x).
  const Pose err = truth.inverse() * result.pose;
  EXPECT_LT(rotation_angle(err), 1e-3);
  EXPECT_NEAR(result.pose.translation().y(), truth.translation().y(), 0.01);
  EXPECT_NEAR(result.pose.translation().z(), truth.translation().z(), 0.01);
  EXPECT_NEAR(result.pose.translation().x(), guess.translation().x(), 0.01);

  // The structured scene constrains every direction: no degeneracy, and the
  // same pose, bit for bit, as with the check off.
  const ScanFeatures full = scene(rng);
  const SemanticLocalMap full_map = map_of(full.edges, full.planars);
  const ScanFeatures full_scan = seen_from(full, truth);
  auto off = settings;
  off.degeneracy_eigenvalue = 0;
  const auto checked = register_scan(full_scan.edges, full_scan.planars, full_map, guess, settings);
  const auto unchecked = register_scan(full_scan.edges, full_scan.planars, full_map, guess, off);
  ASSERT_TRUE(checked.ok);
  EXPECT_EQ(checked.degenerate_directions, 0);
  EXPECT_GT(checked.smallest_eigenvalue, settings.degeneracy_eigenvalue);
  EXPECT_TRUE(checked.pose.matrix() == unchecked.pose.matrix());
  EXPECT_EQ(unchecked.degenerate_directions, 0);  // not counted when off
}

TEST(Registration, NormalizedHessianWeighsRotationAtTheLever) {
  // One plane residual with normal x at 10 m along y: a yaw of phi moves the
  // point by 10 phi along x. At a lever of 10 m, yaw and x translation count alike.
  Eigen::Matrix<double, 1, 6> J;
  const Plane plane{Eigen::Vector3d(0, 10, 0), Eigen::Vector3d::UnitX()};
  point_to_plane_residual(Pose::Identity(), Eigen::Vector3d(0, 10, 0), plane, &J);
  const Eigen::Matrix<double, 6, 6> H = J.transpose() * J;
  const Eigen::Matrix<double, 6, 6> n = normalized_hessian(H, 1, 10.0);
  EXPECT_NEAR(n(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(n(5, 5)), 1.0, 1e-12);
  EXPECT_NEAR(normalized_hessian(4.0 * H, 4, 10.0)(0, 5), n(0, 5), 1e-12);  // per correspondence
}

// The pose and the fit are bit-identical serial and over any number of
// threads: the association writes per feature, and the normal equations and
// the fit are summed in blocks fixed by the number of residuals.
TEST(Registration, SameResultWithAnyNumberOfThreads) {
  std::mt19937 rng(7);
  const ScanFeatures f = scene(rng);
  const SemanticLocalMap map = map_of(f.edges, f.planars);
  Vector6d xi;
  xi << 0.3, -0.2, 0.04, 0.01, -0.008, 0.04;
  const ScanFeatures scan = seen_from(f, se3_exp(xi));
  auto settings = RegistrationSettings::from_config(OdometryConfig{});
  settings.parallel = false;
  settings.inlier_distance = LoopClosureConfig{}.inlier_distance;  // inliers are counted as loop verification counts them
  const auto serial = register_scan(scan.edges, scan.planars, map, Pose::Identity(), settings);
  ASSERT_TRUE(serial.ok);
  ASSERT_GT(serial.inliers, 0);
  ASSERT_GT(scan.edges.size() + scan.planars.size(), 4000u);  // several blocks of residuals
  settings.parallel = true;
  for (const int threads : {1, 2}) {
    tbb::task_arena arena(threads);
    const auto parallel =
        arena.execute([&] { return register_scan(scan.edges, scan.planars, map, Pose::Identity(), settings); });
    EXPECT_TRUE(parallel.pose.matrix() == serial.pose.matrix()) << threads << " threads";
    EXPECT_TRUE(parallel.hessian == serial.hessian) << threads << " threads";
    EXPECT_EQ(parallel.loss, serial.loss) << threads << " threads";
    EXPECT_EQ(parallel.inlier_residual_sum, serial.inlier_residual_sum) << threads << " threads";
    EXPECT_EQ(parallel.inliers, serial.inliers) << threads << " threads";
    EXPECT_EQ(parallel.iterations, serial.iterations) << threads << " threads";
    EXPECT_EQ(parallel.class_squared_residuals, serial.class_squared_residuals) << threads << " threads";
    EXPECT_EQ(parallel.class_dof, serial.class_dof) << threads << " threads";
  }
}

TEST(Registration, PerClassResidualsMeasureEachClassNoise) {
  // The walls measured with 3 cm of noise along their normals, the road
  // exactly: the fit's per-class variances tell them apart.
  std::mt19937 rng(11);
  const ScanFeatures f = scene(rng);
  const SemanticLocalMap map = map_of(f.edges, f.planars);
  ScanFeatures scan = seen_from(f, Pose::Identity());
  const auto road = static_cast<ClassIndex>(to_learning_class(cls::kRoad));
  const auto building = static_cast<ClassIndex>(to_learning_class(cls::kBuilding));
  std::normal_distribution<double> noise(0.0, 0.03);
  for (std::size_t i = 0; i < scan.planars.size(); ++i) {
    if (scan.planars.classes[i] != building) continue;
    Eigen::Vector3d& p = scan.planars.points[i];
    if (std::abs(p.x() - 12.0) < 1e-9) p.x() += noise(rng);  // the wall at x = 12
    else p.y() += noise(rng);                                 // the walls at y = -9 and 14
  }
  const auto result =
      register_scan(scan.edges, scan.planars, map, Pose::Identity(), RegistrationSettings::from_config(OdometryConfig{}));
  ASSERT_TRUE(result.ok);
  ASSERT_GT(result.class_dof[building], 500);
  ASSERT_GT(result.class_dof[road], 200);
  const double wall_sigma = std::sqrt(result.class_squared_residuals[building] / result.class_dof[building]);
  const double road_sigma = std::sqrt(result.class_squared_residuals[road] / result.class_dof[road]);
  // The map's planes are fitted to the noise-free walls; the residual is the
  // added noise (a little less: the fit leans towards the noisy points).
  EXPECT_NEAR(wall_sigma, 0.03, 0.008);
  EXPECT_LT(road_sigma, 0.005);
  // Edges give two degrees of freedom per residual, planes one.
  const auto pole = static_cast<ClassIndex>(to_learning_class(cls::kPole));
  EXPECT_EQ(result.class_dof[pole], 2.0 * result.edge_matches);
}

TEST(Registration, PlaneConstraintRejectsMislabelledPlanes) {
  // Road-labelled points on a wall: with semantics their planes are vertical
  // and get rejected by the constraint.
  const auto road = static_cast<ClassIndex>(to_learning_class(cls::kRoad));
  FeatureCloud wall;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) wall.push_back({10.0, -2.0 + 0.2 * i, -1.0 + 0.2 * j}, road, 0.0f);
  }
  OdometryConfig config;
  const SemanticLocalMap map = map_of(FeatureCloud{}, wall);
  auto settings = RegistrationSettings::from_config(config);
  auto result = register_scan(FeatureCloud{}, wall, map, Pose::Identity(), settings);
  EXPECT_EQ(result.planar_matches, 0);
  EXPECT_GT(result.rejected_by_constraint, 100);
  config.use_semantics = false;
  settings = RegistrationSettings::from_config(config);
  result = register_scan(FeatureCloud{}, wall, map, Pose::Identity(), settings);
  EXPECT_EQ(result.rejected_by_constraint, 0);
  EXPECT_GT(result.planar_matches, 0);
}

TEST(Registration, RefreshedFeaturesAreReassociated) {
  // The scan starts distorted (as if de-skewed with a wrong motion: every
  // point 0.2 m off); the refresh hook replaces it with the true scan after
  // the first round. Re-association thresholds are huge, so only the refresh
  // can cause a second round.
  std::mt19937 rng(7);
  const ScanFeatures f = scene(rng);
  OdometryConfig config;
  const SemanticLocalMap map = map_of(f.edges, f.planars);
  Vector6d xi;
  xi << 0.3, -0.2, 0.02, 0.0, 0.01, 0.03;
  const Pose truth = se3_exp(xi);
  const ScanFeatures correct = seen_from(f, truth);
  ScanFeatures distorted = correct;
  for (auto& p : distorted.edges.points) p.x() += 0.2;
  for (auto& p : distorted.planars.points) p.x() += 0.2;
  auto settings = RegistrationSettings::from_config(config);
  settings.outer_iterations = 3;
  settings.reassociation_min_translation = 10.0;
  settings.reassociation_min_rotation = 1.0;

  ScanFeatures scan = distorted;
  int calls = 0;
  const auto refreshed = register_scan(scan, map, Pose::Identity(), settings, [&](const Pose&, ScanFeatures& s) {
    ++calls;
    if (calls > 1) return false;
    s = correct;
    return true;
  });
  ASSERT_TRUE(refreshed.ok);
  EXPECT_EQ(calls, 2);  // after round 1 (refreshed) and round 2 (not: the small move ends it)
  EXPECT_EQ(refreshed.associations, 2);
  const Pose err = truth.inverse() * refreshed.pose;
  EXPECT_LT(err.translation().norm(), 2e-3);
  EXPECT_LT(rotation_angle(err), 5e-4);

  // Without the refresh the distorted scan stays 0.2 m off after one round.
  const auto plain = register_scan(distorted.edges, distorted.planars, map, Pose::Identity(), settings);
  ASSERT_TRUE(plain.ok);
  EXPECT_EQ(plain.associations, 1);
  EXPECT_GT((truth.inverse() * plain.pose).translation().norm(), 0.1);

  // A refresh may move points but not add or drop any.
  scan = distorted;
  EXPECT_THROW(register_scan(scan, map, Pose::Identity(), settings,
                             [](const Pose&, ScanFeatures& s) {
                               s.planars.push_back(Eigen::Vector3d::Zero(), 0, 0.0f);
                               return true;
                             }),
               std::logic_error);
}

}  // namespace
}  // namespace saloam
