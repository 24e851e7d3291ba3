#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <unordered_map>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "sim/sim_fixture.hpp"

namespace saloam {
namespace {

using testing::scan_at;
using testing::to_world;
using testing::urban_loop;
using testing::urban_world;

TEST(LidarModel, Hdl64eBeamLayout) {
  const LidarModel m = LidarModel::hdl64e(64);
  ASSERT_EQ(m.beams(), 64);
  EXPECT_NEAR(m.elevation_deg.front(), 2.0, 1e-9);
  EXPECT_NEAR(m.elevation_deg.back(), -24.9, 1e-9);
  EXPECT_TRUE(std::is_sorted(m.elevation_deg.rbegin(), m.elevation_deg.rend()));
  EXPECT_EQ(LidarModel::hdl64e(32).beams(), 32);
  EXPECT_EQ(LidarModel::hdl64e(16).beams(), 16);
  EXPECT_THROW(LidarModel::hdl64e(40), ConfigError);
  // Sweep starts behind the car and turns clockwise.
  EXPECT_NEAR(std::abs(m.column_azimuth(0)), M_PI, 0.01);
  EXPECT_NEAR(m.column_azimuth(m.azimuth_steps / 2), 0.0, 0.01);
  EXPECT_GT(m.column_azimuth(10), m.column_azimuth(11));
}

TEST(Scan, KittiLikePointCountAndValidRanges) {
  const SimulatedScan scan = scan_at(120, 64);
  EXPECT_GT(scan.cloud.size(), 95000u);
  EXPECT_LT(scan.cloud.size(), 135000u);
  ASSERT_EQ(scan.ring.size(), scan.cloud.size());
  ASSERT_TRUE(scan.cloud.has_labels);
  for (std::size_t i = 0; i < scan.cloud.size(); ++i) {
    const auto& p = scan.cloud.points[i];
    ASSERT_TRUE(p.allFinite());
    ASSERT_GE(scan.range[i], 2.5f);
    ASSERT_LE(scan.range[i], 120.0f);
    ASSERT_GE(scan.cloud.remission[i], 0.0f);
    ASSERT_LT(scan.cloud.remission[i], 1.0f);
    ASSERT_TRUE(find_semantic_class(scan.cloud.label[i]).has_value()) << scan.cloud.label[i];
    ASSERT_LT(scan.ring[i], 64);
    if (i > 0) {  // ring by ring, each ring in firing order
      ASSERT_TRUE(scan.ring[i] > scan.ring[i - 1] || (scan.ring[i] == scan.ring[i - 1] && scan.column[i] > scan.column[i - 1]));
    }
  }
  // The ground is ~1.73 m below the sensor around the car.
  std::vector<float> road_z;
  for (std::size_t i = 0; i < scan.cloud.size(); ++i) {
    if (scan.cloud.label[i] == cls::kRoad && scan.range[i] < 10) road_z.push_back(scan.cloud.points[i].z());
  }
  ASSERT_GT(road_z.size(), 1000u);
  std::nth_element(road_z.begin(), road_z.begin() + static_cast<std::ptrdiff_t>(road_z.size() / 2), road_z.end());
  EXPECT_NEAR(road_z[road_z.size() / 2], -1.73, 0.15);
}

TEST(Scan, IdenticalForOneAndTwoThreads) {
  SimulatedScan one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = scan_at(300, 16);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = scan_at(300, 16);
  }
  ASSERT_EQ(one.cloud.size(), two.cloud.size());
  EXPECT_EQ(one.cloud.points, two.cloud.points);
  EXPECT_EQ(one.cloud.label, two.cloud.label);
  EXPECT_EQ(one.cloud.remission, two.cloud.remission);
  // Another noise seed changes the scan.
  const SimulatedScan other = scan_at(300, 16, true, 8);
  EXPECT_NE(other.cloud.points, one.cloud.points);
}

TEST(Scan, ClassHistogramLooksLikeSemanticKitti) {
  std::map<std::uint16_t, std::size_t> hist;
  std::size_t total = 0;
  for (std::size_t frame : {40, 190, 340, 490, 640, 790}) {
    const SimulatedScan scan = scan_at(frame, 32);
    for (auto l : scan.cloud.label) ++hist[static_class(l)];
    total += scan.cloud.size();
  }
  auto share = [&](std::uint16_t c) { return static_cast<double>(hist[c]) / static_cast<double>(total); };
  for (std::uint16_t c : {cls::kRoad, cls::kSidewalk, cls::kBuilding, cls::kVegetation, cls::kTerrain}) {
    EXPECT_GT(share(c), 0.03) << class_name(c);
  }
  const double big5 = share(cls::kRoad) + share(cls::kSidewalk) + share(cls::kBuilding) + share(cls::kVegetation) + share(cls::kTerrain);
  EXPECT_GT(big5, 0.65);
  EXPECT_LT(share(cls::kRoad), 0.45);
  for (std::uint16_t c : {cls::kCar, cls::kFence, cls::kTrunk, cls::kPole}) EXPECT_GT(share(c), 0.001) << class_name(c);
  // Streets lined with trees, hedges and fences (SemanticKITTI: vegetation
  // 27 %, fence 7 %); neither may become rare again.
  EXPECT_GT(share(cls::kVegetation), 0.08);
  EXPECT_GT(share(cls::kFence), 0.02);
  // No class outside what the world contains.
  EXPECT_EQ(hist[cls::kUnlabeled], 0u);
}

TEST(World, NoBuildingOrVegetationInTheRoad) {
  const World& world = urban_world();
  std::size_t checked = 0;
  for (const auto& p : world.primitives()) {
    if (p.label != cls::kBuilding && p.label != cls::kVegetation && p.label != cls::kTrunk) continue;
    // Sample the footprint (bounding square of ellipsoids / cylinders, box corners and edges).
    const Eigen::Vector2d c = p.center.cast<double>();
    const Eigen::Vector2d ax(p.cos_yaw, p.sin_yaw), ay(-p.sin_yaw, p.cos_yaw);
    const double hx = p.shape == Shape::kCylinder ? p.half_x : p.half_x, hy = p.shape == Shape::kCylinder ? p.half_x : p.half_y;
    for (double u = -1; u <= 1.001; u += 0.25) {
      for (double v = -1; v <= 1.001; v += 0.25) {
        if (p.shape != Shape::kBox && u * u + v * v > 1.0) continue;
        const Eigen::Vector2d q = c + u * hx * ax + v * hy * ay;
        ASSERT_FALSE(world.in_road(q.x(), q.y())) << class_name(p.label) << " at " << q.transpose();
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 10000u);
  // And in the scans: building and vegetation points never fall on the road.
  for (std::size_t frame : {100, 400, 700}) {
    const SimulatedScan scan = scan_at(frame, 32);
    const auto pts = to_world(scan, frame, 32);
    std::size_t bad = 0, n = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const auto l = scan.cloud.label[i];
      if (l != cls::kBuilding && l != cls::kVegetation && l != cls::kTrunk) continue;
      ++n;
      if (world.road_margin(pts[i].x(), pts[i].y()) < -0.1) ++bad;
    }
    EXPECT_GT(n, 500u);
    EXPECT_EQ(bad, 0u) << "frame " << frame;
  }
  // The driven path itself is road.
  for (std::size_t i = 0; i < urban_loop().size(); i += 25) {
    const auto t = urban_loop()[i].translation();
    EXPECT_TRUE(world.in_road(t.x(), t.y()));
    EXPECT_EQ(world.ground_at(t.x(), t.y()).label, cls::kRoad);
    EXPECT_NEAR(t.z() - world.ground_height(t.x(), t.y()), 1.73, 0.1);
  }
}

TEST(World, RaysStopAtTheFirstGroundCrossing) {
  // Against a brute-force march in 1 cm steps along each ray: a cast ray
  // never passes through the ground, and where the ground is what it hits,
  // it hits it where the fine march first crosses it. The caster's march
  // skips tiles by their highest ground, steps with the ray's clearance and
  // refines the crossing to 3 mm; only the rare grazing ray that dips under a
  // curb's edge between two of its steps may land farther on.
  const World& world = urban_world();
  Rng rng(11);
  const std::vector<Primitive> no_dynamic;
  std::size_t rays = 0, ground_hits = 0, through_ground = 0, off_crossing = 0;
  for (std::size_t frame = 10; frame < urban_loop().size(); frame += 9) {
    const World::RayOrigin origin = world.ray_origin(world.sensor_origin(urban_loop()[frame].translation()));
    const Eigen::Vector3d& o = origin.position;
    for (int k = 0; k < 20; ++k) {
      const double azimuth = rng.uniform(-M_PI, M_PI), elevation = rng.uniform(-25.0, -3.0) * M_PI / 180.0;
      const Eigen::Vector3d d(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                              std::sin(elevation));
      double fine = std::numeric_limits<double>::infinity();
      for (double t = 0.0; t < 120.0; t += 0.01) {
        const Eigen::Vector3d p = o + t * d;
        if (p.z() <= world.ground_height(p.x(), p.y())) {
          fine = t;
          break;
        }
      }
      Rng porous(static_cast<std::uint64_t>(rays));
      const RayHit hit = world.cast_ray(origin, d, 120.0, 0.0, no_dynamic, porous);
      ++rays;
      if (!hit.hit) continue;
      if (hit.range > fine + 0.01) ++through_ground;
      if (is_ground(hit.label) && std::abs(hit.range - fine) > 0.01) ++off_crossing;
      if (is_ground(hit.label)) ++ground_hits;
    }
  }
  EXPECT_GT(ground_hits, rays / 2);
  EXPECT_LE(through_ground, rays / 500) << "of " << rays << " rays";
  EXPECT_LE(off_crossing, ground_hits / 500) << "of " << ground_hits << " ground hits";
}

TEST(Revisit, StaticPointsOfBothPassesCoincide) {
  // Closest pair of poses, one from the start and one from the end of the loop.
  const auto& poses = urban_loop();
  std::size_t best_i = 0, best_j = 0;
  double best = 1e9;
  for (std::size_t i = 30; i < 150; ++i) {
    for (std::size_t j = poses.size() - 250; j < poses.size() - 1; ++j) {
      const double d = (poses[i].translation() - poses[j].translation()).norm();
      if (d < best) best = d, best_i = i, best_j = j;
    }
  }
  ASSERT_LT(best, 1.5);
  auto static_points = [&](const World& world, std::size_t frame) {
    SimulationOptions options;
    options.seed = 7;
    const SweepSpec sweep = sweep_for_frame(poses, frame, options);
    const SimulatedScan scan = simulate_scan(world, LidarModel::hdl64e(32), sweep);
    const auto pts = points_in_world(scan, LidarModel::hdl64e(32), sweep);
    std::vector<Eigen::Vector3d> out;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const auto l = scan.cloud.label[i];
      if ((l == cls::kBuilding || l == cls::kPole || l == cls::kTrunk || l == cls::kFence) && scan.range[i] < 30) out.push_back(pts[i]);
    }
    return out;
  };
  auto median_nn = [](const std::vector<Eigen::Vector3d>& ref, const std::vector<Eigen::Vector3d>& query) {
    const double cell = 0.5;
    std::unordered_map<std::int64_t, std::vector<Eigen::Vector3d>> grid;
    auto key = [&](std::int64_t x, std::int64_t y, std::int64_t z) { return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791); };
    for (const auto& p : ref) {
      grid[key(static_cast<std::int64_t>(std::floor(p.x() / cell)), static_cast<std::int64_t>(std::floor(p.y() / cell)),
               static_cast<std::int64_t>(std::floor(p.z() / cell)))]
          .push_back(p);
    }
    std::vector<double> d;
    for (const auto& q : query) {
      double best = 1.0;
      const auto cx = static_cast<std::int64_t>(std::floor(q.x() / cell)), cy = static_cast<std::int64_t>(std::floor(q.y() / cell)),
                 cz = static_cast<std::int64_t>(std::floor(q.z() / cell));
      for (std::int64_t dx = -1; dx <= 1; ++dx)
        for (std::int64_t dy = -1; dy <= 1; ++dy)
          for (std::int64_t dz = -1; dz <= 1; ++dz) {
            const auto it = grid.find(key(cx + dx, cy + dy, cz + dz));
            if (it == grid.end()) continue;
            for (const auto& p : it->second) best = std::min(best, (p - q).norm());
          }
      d.push_back(best);
    }
    std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
    return d[d.size() / 2];
  };
  const auto first = static_points(urban_world(), best_i), second = static_points(urban_world(), best_j);
  ASSERT_GT(first.size(), 2000u);
  ASSERT_GT(second.size(), 2000u);
  const double same_world = median_nn(first, second);
  EXPECT_LT(same_world, 0.12) << "pass 1 frame " << best_i << ", pass 2 frame " << best_j;
  // Control: a world built with another seed is a different place.
  const World other = build_world(poses, 8);
  const double other_world = median_nn(first, static_points(other, best_j));
  EXPECT_GT(other_world, 3 * same_world);
}

TEST(Dynamic, MovingObjectsMoveAndStaticOnesStay) {
  const World& world = urban_world();
  // Somewhere along the loop an oncoming car passes: find a frame with many moving-car points.
  std::size_t frame = 0;
  std::uint16_t instance = 0;
  for (std::size_t f = 20; f < 900 && instance == 0; f += 20) {
    const SimulatedScan scan = scan_at(f, 16, true, 7, 1024);
    std::map<std::uint16_t, int> count;
    for (std::size_t i = 0; i < scan.cloud.size(); ++i) {
      if (scan.cloud.label[i] == cls::kMovingCar) ++count[scan.cloud.instance[i]];
    }
    int most = 40;
    for (const auto& [inst, n] : count) {
      if (n > most) {
        most = n;
        frame = f;
        instance = inst;
      }
    }
  }
  ASSERT_NE(instance, 0) << "no moving car seen along the whole loop";
  auto centroid = [&](std::size_t f, std::uint16_t label, std::uint16_t inst, int* n_out) {
    const SimulatedScan scan = scan_at(f, 16, true, 7, 1024);
    const auto pts = to_world(scan, f, 16, true, 7, 1024);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int n = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (scan.cloud.label[i] == label && scan.cloud.instance[i] == inst) sum += pts[i], ++n;
    }
    *n_out = n;
    return Eigen::Vector3d(n > 0 ? Eigen::Vector3d(sum / n) : Eigen::Vector3d::Zero());
  };
  int n0 = 0, n1 = 0;
  const Eigen::Vector3d a = centroid(frame, cls::kMovingCar, instance, &n0), b = centroid(frame + 1, cls::kMovingCar, instance, &n1);
  ASSERT_GT(n0, 10);
  ASSERT_GT(n1, 10);
  EXPECT_GT((a - b).head<2>().norm(), 0.4) << "a car at 7-13 m/s moves 0.7-1.3 m in 0.1 s";
  // The agents themselves: positions are a function of time.
  std::vector<Primitive> at0, at1;
  const Eigen::Vector2d here = urban_loop()[frame].translation().head<2>();
  world.agents_at(frame * 0.1, here, 200, at0);
  world.agents_at(frame * 0.1 + 0.5, here, 200, at1);
  ASSERT_FALSE(at0.empty());
  bool moved = false;
  for (const auto& p : at0) {
    for (const auto& q : at1) {
      if (p.instance == q.instance && (p.center - q.center).norm() > 0.4f) moved = true;
    }
  }
  EXPECT_TRUE(moved);
  // Moving persons exist too.
  std::size_t persons = 0;
  for (const auto& agent : world.agents()) persons += agent.label == cls::kMovingPerson ? 1 : 0;
  EXPECT_GT(persons, 10u);
}

TEST(Dynamic, SomeParkedVehiclesDifferBetweenPasses) {
  std::size_t timed = 0, vehicles = 0;
  for (const auto& p : urban_world().primitives()) {
    if (p.label != cls::kCar && p.label != cls::kTruck && p.label != cls::kOtherVehicle) continue;
    ++vehicles;
    EXPECT_NE(p.instance, 0);
    if (std::isfinite(p.time_on) || std::isfinite(p.time_off)) ++timed;
  }
  EXPECT_GT(vehicles, 20u);
  EXPECT_GT(timed, vehicles / 10);
  EXPECT_LT(timed, vehicles / 2);
  // Along the stretch driven twice (the first ~200 m), some vehicles are
  // there on one pass and not on the other, most are there on both. (Within
  // 250 m: parking lanes are rarer since the world follows SemanticKITTI's
  // class mix, and only one parked vehicle changes within 150 m.)
  const auto& poses = urban_loop();
  const double t_first = 50 * 0.1, t_second = (poses.size() - 150) * 0.1;
  const Eigen::Vector2d place = poses[50].translation().head<2>();
  std::set<std::uint16_t> changed, kept;
  for (const auto& p : urban_world().primitives()) {
    if (p.instance == 0 || (p.center.cast<double>() - place).norm() > 250) continue;
    (p.present(t_first) != p.present(t_second) ? changed : kept).insert(p.instance);
  }
  EXPECT_GE(changed.size(), 2u);
  EXPECT_GT(kept.size(), changed.size());
}

TEST(Skew, ReturnsAreDistortedByTheMotionDuringTheSweep) {
  // A straight stretch at speed: pose i to i+1 is ~1 m.
  std::size_t frame = 0;
  double least_turn = 1e9;
  for (std::size_t f = 50; f < 500; ++f) {
    const double turn = rotation_angle(urban_loop()[f].inverse() * urban_loop()[f + 1]);
    if (turn < least_turn && (urban_loop()[f + 1].translation() - urban_loop()[f].translation()).norm() > 0.7) {
      least_turn = turn;
      frame = f;
    }
  }
  const double motion = (urban_loop()[frame + 1].translation() - urban_loop()[frame].translation()).norm();
  const SimulatedScan on = scan_at(frame, 32, true), off = scan_at(frame, 32, false);
  std::map<std::pair<int, int>, Eigen::Vector3f> off_points;
  for (std::size_t i = 0; i < off.cloud.size(); ++i) off_points[{off.ring[i], off.column[i]}] = off.cloud.points[i];
  // Same ray (ring, column) with and without skew, hitting static upright
  // things: late columns (behind the car) were fired ~0.1 s later, ~1 m further on.
  const int columns = 2083;
  std::vector<double> early, late;
  for (std::size_t i = 0; i < on.cloud.size(); ++i) {
    const auto l = on.cloud.label[i];
    if (l != cls::kBuilding && l != cls::kFence && l != cls::kVegetation && l != cls::kTrunk && l != cls::kCar &&
        l != cls::kPole) {
      continue;
    }
    const auto it = off_points.find({on.ring[i], on.column[i]});
    if (it == off_points.end() || on.range[i] > 50) continue;
    const double d = (on.cloud.points[i] - it->second).norm();
    if (on.column[i] < columns / 10) early.push_back(d);
    if (on.column[i] > columns - columns / 10) late.push_back(d);
  }
  ASSERT_GT(early.size(), 20u);
  ASSERT_GT(late.size(), 20u);
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  EXPECT_LT(median(early), 0.15 * motion + 0.05);
  EXPECT_GT(median(late), 0.4 * motion);
  // De-skewed with the true motion, skew-on road points lie on the road surface
  // just like skew-off ones (the distortion is exactly the sensor motion).
  const auto world_on = to_world(on, frame, 32, true);
  std::size_t on_road = 0, off_surface = 0;
  for (std::size_t i = 0; i < on.cloud.size(); ++i) {
    if (on.cloud.label[i] != cls::kRoad || on.range[i] > 20) continue;
    ++on_road;
    if (std::abs(world_on[i].z() - urban_world().ground_height(world_on[i].x(), world_on[i].y())) > 0.1) ++off_surface;
  }
  EXPECT_GT(on_road, 500u);
  EXPECT_LT(off_surface, on_road / 100);
}

}  // namespace
}  // namespace saloam
