// Buildings and their plots along the street (see world_builder.hpp): the
// house, its front garden (property line, bushes and trees, a car in the
// driveway, shrubs along the facade) and the planting in the gap to the next.

#include <algorithm>
#include <cmath>
#include <limits>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/sim/world_builder.hpp"

namespace saloam {

using namespace world_building;

void WorldBuilder::place_buildings(double total_time) {
  for (int side = -1; side <= 1; side += 2) {
    Rng rng(hash3(seed_, kSaltBuildings, static_cast<std::uint64_t>(side + 5)));
    walk(rng.uniform(0, 10), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
      return building_plot(p, dir, side, rng, total_time);
    });
  }
}

double WorldBuilder::building_plot(const Eigen::Vector2d& p, const Eigen::Vector2d& dir, int side, Rng& rng,
                                   double total_time) {
  const Eigen::Vector2d left(-dir.y(), dir.x());
  const Eigen::Vector2d probe = p + side * left * 8.0;
  const World::Zone z = w_->zone_at(probe.x(), probe.y());
  if (z.sidewalk == 0 && !rng.chance(0.12)) return rng.uniform(15, 40);  // rural: mostly open land
  double length = rng.chance(0.25) ? rng.uniform(25, 45) : rng.uniform(9, 25);
  const double depth = rng.uniform(8, 18);
  const double pick = rng.uniform();
  const double height = pick < 0.12 ? rng.uniform(5, 8) : (pick < 0.75 ? rng.uniform(8, 16) : rng.uniform(16, 25));
  // Front gardens, or (in the older blocks) the facade at the back of the
  // sidewalk: no strip of grass left between them.
  const double setback = rng.chance(0.65) ? rng.uniform(3.5, 12) : rng.uniform(0.25, 0.45);
  const double yaw = rng.uniform(-0.035, 0.035);
  const double edge = street_edge(probe, side);
  for (int attempt = 0; attempt < 2; ++attempt, length *= 0.55) {
    const Eigen::Vector2d axis = Eigen::Rotation2Dd(yaw) * dir;
    const Eigen::Vector2d mleft(-axis.y(), axis.x());
    const Eigen::Vector2d c = p + 0.5 * length * axis + side * mleft * (edge + setback + 0.5 * depth);
    if (!rect_free(c, axis, 0.5 * length + 0.1, 0.5 * depth + 0.1, 0.1, false)) continue;
    add_building(c, axis, 0.5 * length, 0.5 * depth, height, rng);
    mark_rect(c, axis, 0.5 * length + 0.8, 0.5 * depth + 0.8);
    const Plot plot{p, axis, mleft, side, length, depth, edge, setback};
    front_garden(plot, rng, total_time);
    const double gap = rng.chance(0.4) ? rng.uniform(0.0, 1.0) : rng.uniform(2, 14);
    gap_planting(plot, gap, rng);
    return length + gap;
  }
  return 4.0;
}

void WorldBuilder::front_garden(const Plot& plot, Rng& rng, double total_time) {
  const auto& [p, axis, mleft, side, length, depth, edge, setback] = plot;
  // Front yard: hedge or fence along the property line at the back of the sidewalk.
  const Eigen::Vector2d yard = p + 0.5 * length * axis + side * mleft * edge;
  if (setback > 2.0) property_line(yard, axis, side * mleft, 0.5 * length, rng);
  // Garden: bushes and trees between the property line and the house
  // (front gardens in KITTI's towns are densely planted).
  // (Each bush wholly between the property line, 1.6 m in, and the
  // house, 0.8 m clear of it.)
  for (int k = 0; setback > 3.0 && k < static_cast<int>(length * setback / 3.0); ++k) {
    const double r = std::min(rng.uniform(0.8, 2.6), 0.5 * (setback - 2.4));
    const double near = edge + 1.6 + r, far = edge + setback - 0.8 - r;
    if (r < 0.4 || far < near) continue;
    const Eigen::Vector2d g = p + rng.uniform(0.1, 0.9) * length * axis + side * mleft * rng.uniform(near, far);
    if (!rect_free(g, axis, r, r, 0.5, false)) continue;
    if (r > 1.0 && rng.chance(0.45)) add_tree(g, r + 1.2, rng); else add_bush(g, r, rng);
    mark_rect(g, axis, r, r);
  }
  driveway_car(plot, rng, total_time);
  // Shrubs along the house front (foundation planting) on some plots.
  if (setback > 2.5 && rng.chance(0.5)) {
    const Eigen::Vector2d front = p + 0.5 * length * axis + side * mleft * (edge + setback - 0.6);
    add_hedge(front, axis, 0.5 * length - 0.5, 0.45, rng.uniform(0.7, 1.6), rng);
  }
}

// A car in the driveway of some front gardens (most of KITTI's parked cars
// are off the parking lanes, which hold 1.5 % of its points).
void WorldBuilder::driveway_car(const Plot& plot, Rng& rng, double total_time) {
  const auto& [p, axis, mleft, side, length, depth, edge, setback] = plot;
  if (setback > 5.5 && rng.chance(0.7)) {
    const Eigen::Vector2d d = p + rng.uniform(0.15, 0.85) * length * axis + side * mleft * (edge + 1.7 + 2.5);
    const double car_length = rng.uniform(3.9, 4.9);
    if (rect_free(d, mleft, 0.5 * car_length + 0.15, 1.05, 0.5, false)) {
      add_vehicle(d, mleft * (rng.chance(0.5) ? 1.0 : -1.0), cls::kCar, car_length, rng.uniform(1.7, 1.9),
                  rng.uniform(1.4, 1.65), rng, total_time);
      mark_rect(d, mleft, 0.5 * car_length + 0.15, 1.05);
    }
  }
}

// Trees and shrubs fill most gaps between houses.
void WorldBuilder::gap_planting(const Plot& plot, double gap, Rng& rng) {
  const auto& [p, axis, mleft, side, length, depth, edge, setback] = plot;
  if (gap > 2.5 && rng.chance(0.8)) {
    const double r = std::min(0.5 * gap - 0.4, rng.uniform(1.5, 3.5));
    const Eigen::Vector2d g = p + (length + 0.5 * gap) * axis + side * mleft * (edge + setback + rng.uniform(1.0, 0.5 * depth + 2.0));
    if (r > 0.8 && rect_free(g, {1, 0}, r, r, 1.0, false)) {
      if (rng.chance(0.6)) add_tree(g, r + 0.8, rng); else add_bush(g, r, rng);
      mark_rect(g, {1, 0}, r, r);
    }
  }
}

void WorldBuilder::add_building(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy, double height, Rng& rng) {
  const double g = lowest_ground(c, axis, hx, hy);
  Primitive b = box(cls::kBuilding, c, axis, hx, hy, g - 0.5, g + height, rng.uniform(0.12, 0.42));
  b.facade.floor_height = static_cast<float>(rng.uniform(2.8, 3.6));
  b.facade.window_spacing = static_cast<float>(rng.uniform(2.4, 3.8));
  b.facade.window_width = static_cast<float>(std::min(b.facade.window_spacing - 0.6, rng.uniform(0.9, 1.8)));
  b.facade.window_height = static_cast<float>(rng.uniform(1.1, 1.8));
  b.facade.recess = static_cast<float>(rng.uniform(0.12, 0.35));
  b.facade.glass_dropout = static_cast<float>(rng.uniform(0.25, 0.7));
  if (rng.chance(0.15)) b.facade.floor_height = 0;  // plain wall (warehouse, garage)
  w_->add_object(b);
  // A plinth that sticks out a little: facades are not perfect planes.
  if (rng.chance(0.5)) {
    w_->add_object(box(cls::kBuilding, c, axis, hx + 0.12, hy + 0.12, g - 0.5, g + rng.uniform(0.4, 1.0),
                                 b.remission * 0.8));
  }
  // Pilasters or balconies every few metres on some buildings.
  if (rng.chance(0.35) && height > 7) {
    const Eigen::Vector2d side(-axis.y(), axis.x());
    const double spacing = rng.uniform(4, 8);
    for (double u = -hx + 1; u < hx - 1; u += spacing) {
      for (int s = -1; s <= 1; s += 2) {
        const Eigen::Vector2d pc = c + u * axis + s * (hy + 0.2) * side;
        w_->add_object(box(cls::kBuilding, pc, axis, 0.25, 0.2, g, g + height, b.remission));
      }
    }
  }
  // Stepped upper storey.
  if (rng.chance(0.3) && hx > 4 && hy > 4) {
    Primitive top = b;
    top.half_x = static_cast<float>(hx - rng.uniform(1, 3));
    top.half_y = static_cast<float>(hy - rng.uniform(1, 3));
    top.z_min = static_cast<float>(g + height);
    top.z_max = static_cast<float>(g + height + rng.uniform(3, 6));
    w_->add_object(top);
  }
}

double WorldBuilder::lowest_ground(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy) const {
  double g = std::numeric_limits<double>::infinity();
  for_rect(c, axis, hx, hy, [&](const Eigen::Vector2d& p) {
    g = std::min(g, ground(p));
    return true;
  });
  return g;
}

void WorldBuilder::property_line(const Eigen::Vector2d& front, const Eigen::Vector2d& axis, const Eigen::Vector2d& away,
                                 double half_length, Rng& rng) {
  const double pick = rng.uniform();
  if (pick < 0.08) return;
  if (pick < 0.58) {
    // Privacy hedges, mostly above the sensor's 1.73 m: the lawn behind them
    // is out of sight of every beam pointing down.
    const double half_w = rng.uniform(0.35, 0.7);
    add_hedge(front + away * (kLineGap + half_w), axis, half_length, half_w, rng.uniform(1.5, 2.6), rng);
  } else {
    const Eigen::Vector2d c = front + away * (kLineGap + kFenceCheckHalfWidth);
    add_fence(c, axis, half_length, rng.uniform(1.0, 1.9), 0.2, rng);
    if (rng.chance(0.75)) planting_behind(c, axis, away, half_length, rng);
  }
}

}  // namespace saloam
