// The driven path and the ground raster of the street world (see
// world_builder.hpp): road centre lines, the distance and side of every cell
// to the nearest one, the ground's height, the street layout (zones) and
// bumps, and bounds on how the ground rises for the ray marcher.

#include <algorithm>
#include <cmath>
#include <limits>

#include "saloam/core/error.hpp"
#include "saloam/sim/world_builder.hpp"

namespace saloam {

using namespace world_building;

namespace {
// How much the plane of a pose's x and y axes (the car's, seated on the
// road) rises per metre horizontally to the left of its heading.
double cross_slope_of(const Pose& pose) {
  const Eigen::Vector3d up = pose.linear().col(2);
  const Eigen::Vector3d forward = pose.linear().col(0);
  const Eigen::Vector2d heading = forward.head<2>().norm() > 1e-9 ? Eigen::Vector2d(forward.head<2>().normalized()) : Eigen::Vector2d(1, 0);
  const Eigen::Vector3d left(-heading.y(), heading.x(), 0.0);
  return up.z() > 1e-3 ? -up.dot(left) / up.z() : 0.0;
}
}  // namespace

void WorldBuilder::build_path(const std::vector<Pose>& trajectory) {
  const double h = options_.sensor_height;
  path_.ego_s.reserve(trajectory.size());
  double s = 0;
  Eigen::Vector3d prev = trajectory.front().translation() - Eigen::Vector3d(0, 0, h);
  double prev_cross = cross_slope_of(trajectory.front());
  path_.points.push_back(prev);
  path_.s.push_back(0);
  path_.ego_s.push_back(0);
  path_.cross_slope.push_back(prev_cross);
  for (std::size_t i = 1; i < trajectory.size(); ++i) {
    const Eigen::Vector3d p = trajectory[i].translation() - Eigen::Vector3d(0, 0, h);
    const double cross = cross_slope_of(trajectory[i]);
    const double len = (p - prev).norm();
    if (len > kPassJump) {
      // The jump from one pass to the next (SimulationOptions::passes):
      // no road along it, no arc length (moving objects do not travel it).
      path_.points.push_back(p);
      path_.s.push_back(s);
      path_.ego_s.push_back(s);
      path_.cross_slope.push_back(cross);
      prev = p;
      prev_cross = cross;
      continue;
    }
    const int pieces = std::max(1, static_cast<int>(std::ceil(len / 0.5)));
    if (len > 1e-6) {
      for (int k = 1; k <= pieces; ++k) {
        const double a = static_cast<double>(k) / pieces;
        path_.points.push_back(prev + a * (p - prev));
        path_.s.push_back(s + a * len);
        path_.cross_slope.push_back(prev_cross + a * (cross - prev_cross));
      }
    }
    s += len;
    path_.ego_s.push_back(s);
    prev = p;
    prev_cross = cross;
  }
}

void WorldBuilder::build_ground() {
  lay_out_raster();
  std::vector<Eigen::Vector3d> centres;
  std::vector<Eigen::Vector2d> centre_dirs;
  road_centre_lines(centres, centre_dirs);
  const std::vector<std::int32_t> source = nearest_centres(centres);
  side_of_path(source, centres, centre_dirs);
  ground_heights(source, centres);
  street_zones_and_bumps();
  bound_ground_rise();
  occupied_.assign(ground_.distance.size(), 0);
}

void WorldBuilder::lay_out_raster() {
  const auto& opt = options_;
  Eigen::Vector2d lo = path_.points.front().head<2>(), hi = lo;
  for (const auto& p : path_.points) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  lo.array() -= opt.margin;
  hi.array() += opt.margin;
  ground_.origin = lo;
  const double cell = opt.ground_cell;
  ground_.nx = static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)) + 1;
  ground_.ny = static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)) + 1;
  const std::size_t n = static_cast<std::size_t>(ground_.nx) * static_cast<std::size_t>(ground_.ny);
  if (n > 200'000'000ull) throw ConfigError("trajectory spans too large an area for the simulator's ground raster");
}

void WorldBuilder::road_centre_lines(std::vector<Eigen::Vector3d>& centres, std::vector<Eigen::Vector2d>& dirs) {
  for (std::size_t k = 0; k < path_.points.size(); ++k) {
    const std::size_t k0 = k > 0 ? k - 1 : k, k1 = std::min(path_.points.size() - 1, k + 1);
    Eigen::Vector2d dir = (path_.points[k1] - path_.points[k0]).head<2>();
    centres.push_back(path_.points[k]);
    dirs.push_back(dir.norm() > 1e-9 ? Eigen::Vector2d(dir.normalized()) : Eigen::Vector2d(1, 0));
  }
  add_side_streets(centres, dirs);
}

// Seeds the cells on the lines, then a two-pass propagation (a feature
// transform, close to the exact Euclidean one).
std::vector<std::int32_t> WorldBuilder::nearest_centres(const std::vector<Eigen::Vector3d>& centres) {
  const double cell_size = options_.ground_cell;
  const Eigen::Vector2d lo = ground_.origin;
  const std::size_t n = static_cast<std::size_t>(ground_.nx) * static_cast<std::size_t>(ground_.ny);
  std::vector<std::int32_t> source(n, -1);
  ground_.distance.assign(n, std::numeric_limits<float>::infinity());
  for (std::size_t k = 0; k < centres.size(); ++k) {
    const int ix = static_cast<int>((centres[k].x() - lo.x()) / cell_size);
    const int iy = static_cast<int>((centres[k].y() - lo.y()) / cell_size);
    if (ix < 0 || iy < 0 || ix >= ground_.nx || iy >= ground_.ny) continue;
    const double dist = (cell_centre(ix, iy) - centres[k].head<2>()).norm();
    const std::size_t i = cell(ix, iy);
    if (dist < ground_.distance[i]) {
      ground_.distance[i] = static_cast<float>(dist);
      source[i] = static_cast<std::int32_t>(k);
    }
  }
  auto relax = [&](int ix, int iy, int jx, int jy) {
    if (jx < 0 || jy < 0 || jx >= ground_.nx || jy >= ground_.ny) return;
    const std::int32_t src = source[cell(jx, jy)];
    if (src < 0) return;
    const double dist = (cell_centre(ix, iy) - centres[static_cast<std::size_t>(src)].head<2>()).norm();
    const std::size_t i = cell(ix, iy);
    if (dist < ground_.distance[i]) {
      ground_.distance[i] = static_cast<float>(dist);
      source[i] = src;
    }
  };
  for (int pass = 0; pass < 2; ++pass) {
    for (int iy = 0; iy < ground_.ny; ++iy) {
      for (int ix = 0; ix < ground_.nx; ++ix) {
        relax(ix, iy, ix - 1, iy);
        relax(ix, iy, ix - 1, iy - 1);
        relax(ix, iy, ix, iy - 1);
        relax(ix, iy, ix + 1, iy - 1);
      }
      for (int ix = ground_.nx - 1; ix >= 0; --ix) relax(ix, iy, ix + 1, iy);
    }
    for (int iy = ground_.ny - 1; iy >= 0; --iy) {
      for (int ix = ground_.nx - 1; ix >= 0; --ix) {
        relax(ix, iy, ix + 1, iy);
        relax(ix, iy, ix + 1, iy + 1);
        relax(ix, iy, ix, iy + 1);
        relax(ix, iy, ix - 1, iy + 1);
      }
      for (int ix = 0; ix < ground_.nx; ++ix) relax(ix, iy, ix - 1, iy);
    }
  }
  return source;
}

// Signed lateral offset: which side of the nearest path point's direction.
void WorldBuilder::side_of_path(const std::vector<std::int32_t>& source, const std::vector<Eigen::Vector3d>& centres,
                                const std::vector<Eigen::Vector2d>& dirs) {
  ground_.lateral.resize(source.size());
  for (int iy = 0; iy < ground_.ny; ++iy) {
    for (int ix = 0; ix < ground_.nx; ++ix) {
      const std::size_t i = cell(ix, iy);
      const auto k = static_cast<std::size_t>(source[i]);
      const Eigen::Vector2d& dir = dirs[k];
      const Eigen::Vector2d rel = cell_centre(ix, iy) - centres[k].head<2>();
      const double cross = dir.x() * rel.y() - dir.y() * rel.x();
      ground_.lateral[i] = cross >= 0 ? ground_.distance[i] : -ground_.distance[i];
    }
  }
}

// Height of the nearest path point, smoothed so that two passes at slightly
// different heights meet without a step. Ground-truth trajectories are not
// always consistent in height (KITTI 08 climbs 9 m in its first 13 m with a
// level car, and passes its start again 6 m higher): no single ground lies
// 1.73 m under every pose there, so the sensor keeps a physical clearance
// above this ground (World::sensor_origin).
//
// On a hillside (WorldOptions::hillside) the road tilts across with the
// poses' roll, and away from it the ground turns into the broad relief (see
// there); the blurs are linear, so a steady grade or cross-slope passes
// through them unchanged and the ground under the path stays the path's.
void WorldBuilder::ground_heights(const std::vector<std::int32_t>& source, const std::vector<Eigen::Vector3d>& centres) {
  const std::size_t n = source.size();
  const bool hillside = options_.hillside;
  ground_.height.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(source[i]);
    double z = centres[k].z();
    if (hillside && k < path_.cross_slope.size()) {  // a side street's centre lies beyond the path's points: level
      const double bank = WorldOptions::kHillsideBankWidth;
      z += std::clamp(static_cast<double>(ground_.lateral[i]), -bank, bank) * path_.cross_slope[k];
    }
    ground_.height[i] = static_cast<float>(z);
  }
  box_blur(ground_.height, 4);
  box_blur(ground_.height, 4);
  if (!hillside) return;
  // Two boxes of +-25 cells: a triangle-like average over +-50 m.
  std::vector<float> relief = ground_.height;
  const int radius = static_cast<int>(std::lround(25.0 / options_.ground_cell));
  box_blur(relief, radius);
  box_blur(relief, radius);
  const double near = WorldOptions::kHillsideNear, far = WorldOptions::kHillsideFar;
  for (std::size_t i = 0; i < n; ++i) {
    const double u = std::clamp((ground_.distance[i] - near) / (far - near), 0.0, 1.0);
    const double blend = u * u * (3.0 - 2.0 * u);
    ground_.height[i] = static_cast<float>(ground_.height[i] + blend * (relief[i] - ground_.height[i]));
  }
}

World::Zone WorldBuilder::street_layout(const Eigen::Vector2d& c) const {
  World::Zone z;
  const bool rural = noise_at(hash_combine(seed_, kSaltRural), c.x(), c.y(), 260.0) > kRuralNoise;
  // Right-hand traffic: the path runs in the right lane; the oncoming lane
  // (2.8 m further left) and, on avenues, one more lane lie left. KITTI's
  // towns are mostly narrow two-lane streets: avenues are rare.
  z.road_right = static_cast<float>(1.5 + 0.4 * noise_at(hash_combine(seed_, kSaltRoad), c.x(), c.y(), 140.0));
  const bool avenue = noise_at(hash_combine(seed_, kSaltRoad + 1000), c.x(), c.y(), 300.0) > 0.9;
  z.road_left = z.road_right + 2.8f + (avenue ? 3.3f : 0.0f);
  const double park = noise_at(hash_combine(seed_, kSaltParking), c.x(), c.y(), 55.0);
  const double lot = noise_at(hash_combine(seed_, kSaltLot), c.x(), c.y(), 70.0);
  z.parking = 0.0f;
  // Parking lanes and lots are rare in SemanticKITTI (1.5 % of all points,
  // against 4 % for cars: most of its parked cars stand in driveways, yards
  // and on the road's edge).
  if (!rural && park > 0.75) z.parking = 2.3f;
  if (!rural && lot > 0.985) z.parking = 12.0f;
  // Elsewhere in town most streets have cars parked on the road along both
  // curbs (no marked lane: SemanticKITTI labels the ground road).
  if (!rural && z.parking == 0 && park > kCurbParkingNoise) {
    z.curb_parking = kCurbParkingWidth;
    z.road_right += z.curb_parking;
    z.road_left += z.curb_parking;
  }
  z.sidewalk = rural ? 0.0f
                     : static_cast<float>(1.4 + 1.2 * noise_at(hash_combine(seed_, kSaltSidewalk), c.x(), c.y(), 90.0));
  const double verge = noise_at(hash_combine(seed_, kSaltVerge), c.x(), c.y(), 45.0);
  z.verge = rural || verge < 0.72 ? 0 : (verge < 0.86 ? 1 : 2);
  return z;
}

float WorldBuilder::bump_at(const Eigen::Vector2d& c) const {
  return static_cast<float>(0.7 * noise_at(hash_combine(seed_, kSaltBump), c.x(), c.y(), 14.0) +
                            0.8 * noise_at(hash_combine(seed_, kSaltBump2), c.x(), c.y(), 55.0) - 0.6);
}

void WorldBuilder::street_zones_and_bumps() {
  const std::size_t n = ground_.distance.size();
  ground_.zones.resize(n);
  ground_.bump.resize(n);
  for (int iy = 0; iy < ground_.ny; ++iy) {
    for (int ix = 0; ix < ground_.nx; ++ix) {
      const Eigen::Vector2d c = cell_centre(ix, iy);
      const std::size_t i = cell(ix, iy);
      ground_.zones[i] = street_layout(c);
      ground_.bump[i] = bump_at(c);
    }
  }
}

// Bounds on how fast the ground surface rises along any horizontal
// direction [m per m], tile by tile, away from curbs and zone edges
// (World::kGroundStep): the height and the bump are bilinear between raster
// nodes, so each changes along a direction at most by its largest x step
// plus its largest y step per cell; the verge fades the bump in over 12 m.
// And on how high the ground gets in each tile: a bilinear value is at most
// its largest node. A tile's bounds cover the raster patches that reach
// into it.
void WorldBuilder::bound_ground_rise() {
  const int tile = World::kRiseTile;
  ground_.rise_nx = (ground_.nx + tile - 1) / tile;
  ground_.rise_ny = (ground_.ny + tile - 1) / tile;
  const std::size_t tiles = static_cast<std::size_t>(ground_.rise_nx) * static_cast<std::size_t>(ground_.rise_ny);
  ground_.rise.assign(tiles, 0.0f);
  // Highest raster height and bump reaching into each tile: the ground
  // (World::ground_from) is at most their sum plus the curb.
  std::vector<float> top_height(tiles, -std::numeric_limits<float>::infinity()), top_bump(tiles, 0.0f);
  for (int iy = 0; iy < ground_.ny; ++iy) {
    for (int ix = 0; ix < ground_.nx; ++ix) {
      const std::size_t i = cell(ix, iy);
      float step_height = 0.0f, step_bump = 0.0f;
      for (const std::size_t j : {ix + 1 < ground_.nx ? cell(ix + 1, iy) : i, iy + 1 < ground_.ny ? cell(ix, iy + 1) : i}) {
        step_height = std::max(step_height, std::abs(ground_.height[j] - ground_.height[i]));
        step_bump = std::max(step_bump, std::abs(ground_.bump[j] - ground_.bump[i]));
      }
      const float rise = static_cast<float>(2.0 * (step_height + step_bump) / options_.ground_cell +
                                            std::abs(ground_.bump[i]) / 12.0 + 1e-3);
      // The node's patches span [ix - 1, ix + 1]: every tile they reach.
      for (int ty = std::max(0, iy - 1) / tile; ty <= std::min(ground_.ny - 1, iy + 1) / tile; ++ty) {
        for (int tx = std::max(0, ix - 1) / tile; tx <= std::min(ground_.nx - 1, ix + 1) / tile; ++tx) {
          const std::size_t t = static_cast<std::size_t>(ty) * static_cast<std::size_t>(ground_.rise_nx) + static_cast<std::size_t>(tx);
          ground_.rise[t] = std::max(ground_.rise[t], rise);
          top_height[t] = std::max(top_height[t], ground_.height[i]);
          top_bump[t] = std::max(top_bump[t], ground_.bump[i]);
        }
      }
    }
  }
  ground_.top.resize(tiles);
  for (std::size_t t = 0; t < tiles; ++t) {
    ground_.top[t] = static_cast<float>(top_height[t] + std::max(World::kCurbHeight, World::kParkingRise) + top_bump[t] + 1e-3);
  }
}

void WorldBuilder::add_side_streets(std::vector<Eigen::Vector3d>& centres, std::vector<Eigen::Vector2d>& dirs) {
  Rng rng(hash_combine(seed_, kSaltRoad + 7));
  PointSet junctions;
  const double len = path_.length();
  for (double s = rng.uniform(20, 80); s < len - 10; s += rng.uniform(100, 250)) {
    Eigen::Vector3d pos;
    Eigen::Vector2d dir;
    path_.point(s, pos, dir);
    // Not on open land, and one junction per place even where the path passes twice.
    if (noise_at(hash_combine(seed_, kSaltRural), pos.x(), pos.y(), 260.0) > kRuralNoise) continue;
    if (!far_from(junctions, pos.head<2>(), 50.0)) continue;
    // Only on straight stretches: a side street off a bend would run askew.
    Eigen::Vector3d before, after;
    Eigen::Vector2d dir_before, dir_after;
    path_.point(s - 15.0, before, dir_before);
    path_.point(s + 15.0, after, dir_after);
    if (dir_before.dot(dir_after) < std::cos(0.25)) continue;
    junctions.push_back(pos.head<2>());
    const Eigen::Vector2d left(-dir.y(), dir.x());
    const double pick = rng.uniform();
    for (int side = -1; side <= 1; side += 2) {
      if ((pick < 0.35 && side > 0) || (pick > 0.7 && side < 0)) continue;  // T-junctions or crossings
      const double length = rng.uniform(40, 90);
      // The stub's centre line runs in its right lane, like the path: shift it
      // so that its road is centred on the crossing.
      const Eigen::Vector2d out = side * left;
      const Eigen::Vector2d start = pos.head<2>() - Eigen::Vector2d(-out.y(), out.x()) * 1.6;
      for (double u = 2.0; u < length; u += 0.5) {
        centres.emplace_back(start.x() + u * out.x(), start.y() + u * out.y(), pos.z());
        dirs.push_back(out);
      }
    }
  }
}

// Separable box filter with running sums (O(n) whatever the radius); the
// window is clipped at the raster border.
void WorldBuilder::box_blur(std::vector<float>& f, int radius) const {
  const int nx = ground_.nx, ny = ground_.ny;
  std::vector<float> tmp(f.size());
  std::vector<double> line;
  auto blur_line = [&](int count, auto&& get, auto&& set) {
    line.assign(static_cast<std::size_t>(count) + 1, 0.0);
    for (int k = 0; k < count; ++k) line[static_cast<std::size_t>(k) + 1] = line[static_cast<std::size_t>(k)] + get(k);
    for (int k = 0; k < count; ++k) {
      const int a = std::max(0, k - radius), b = std::min(count - 1, k + radius);
      set(k, static_cast<float>((line[static_cast<std::size_t>(b) + 1] - line[static_cast<std::size_t>(a)]) / (b - a + 1)));
    }
  };
  for (int iy = 0; iy < ny; ++iy) {
    const std::size_t row = static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx);
    blur_line(nx, [&](int k) { return static_cast<double>(f[row + static_cast<std::size_t>(k)]); },
              [&](int k, float v) { tmp[row + static_cast<std::size_t>(k)] = v; });
  }
  for (int ix = 0; ix < nx; ++ix) {
    auto at = [&](int k) { return static_cast<std::size_t>(k) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(ix); };
    blur_line(ny, [&](int k) { return static_cast<double>(tmp[at(k)]); }, [&](int k, float v) { f[at(k)] = v; });
  }
}

}  // namespace saloam
