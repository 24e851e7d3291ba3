// The street world's construction (see world_builder.hpp for its parts):
// the order of the steps, the placement helpers every part uses, and the
// ray-casting grid.

#include <algorithm>
#include <cmath>

#include "saloam/core/error.hpp"
#include "saloam/sim/world_builder.hpp"

namespace saloam {

using namespace world_building;

World build_world(const std::vector<Pose>& lidar_trajectory, std::uint64_t seed, const WorldOptions& options) {
  if (lidar_trajectory.empty()) throw ConfigError("cannot build a world along an empty trajectory");
  World world;
  world.options_ = options;
  world.seed_ = seed;
  WorldBuilder builder(world, seed);
  builder.build_path(lidar_trajectory);
  builder.build_ground();
  const double total_time = static_cast<double>(lidar_trajectory.size() - 1) * options.frame_period;
  builder.place_buildings(total_time);
  builder.place_parked_vehicles(total_time);
  builder.place_street_furniture();
  builder.place_boundaries();
  builder.place_trees();
  builder.place_structures();
  builder.plant_verges();
  builder.place_agents(total_time);
  builder.build_grid();
  return world;
}

double WorldBuilder::street_edge(const Eigen::Vector2d& p, int side) const {
  const World::Zone z = w_.zone_at(p.x(), p.y());
  return z.road(side) + z.parking + z.sidewalk;
}

bool WorldBuilder::inside_grid(const Eigen::Vector2d& p) const {
  return p.x() > w_.origin_.x() + 1 && p.y() > w_.origin_.y() + 1 &&
         p.x() < w_.origin_.x() + (w_.nx_ - 1) * w_.options_.ground_cell &&
         p.y() < w_.origin_.y() + (w_.ny_ - 1) * w_.options_.ground_cell;
}

bool WorldBuilder::rect_free(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy, double clearance,
                             bool road_only) const {
  return for_rect(c, axis, hx, hy, [&](const Eigen::Vector2d& p) {
    if (!inside_grid(p)) return false;
    const World::Zone z = w_.zone_at(p.x(), p.y());
    // Off the street: a margin from the road even where there is no sidewalk.
    const double limit = road_only ? clearance : std::max(z.parking + z.sidewalk + clearance, kRoadsideMargin);
    return w_.road_margin(p.x(), p.y()) >= limit && occupied_[w_.cell_index(p.x(), p.y())] == 0;
  });
}

void WorldBuilder::mark_rect(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy) {
  if (run_marks_) {
    run_marks_->push_back({c, axis, hx, hy});
    return;
  }
  for_rect(c, axis, hx, hy, [&](const Eigen::Vector2d& p) {
    if (inside_grid(p)) occupied_[w_.cell_index(p.x(), p.y())] = 1;
    return true;
  });
}

bool WorldBuilder::clear_of_road(const Eigen::Vector2d& c, double r, double clearance) const {
  return for_rect(c, {1, 0}, r, r, [&](const Eigen::Vector2d& p) {
    return inside_grid(p) && w_.road_margin(p.x(), p.y()) >= clearance;
  });
}

bool WorldBuilder::disc_free(const Eigen::Vector2d& c, double r, double road_clearance) const {
  return rect_free(c, {1, 0}, r, r, road_clearance, true);
}

Primitive WorldBuilder::box(std::uint16_t label, const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy,
                            double z0, double z1, double remission) const {
  Primitive p;
  p.shape = Shape::kBox;
  p.label = label;
  p.center = c.cast<float>();
  p.cos_yaw = static_cast<float>(axis.x());
  p.sin_yaw = static_cast<float>(axis.y());
  p.half_x = static_cast<float>(hx);
  p.half_y = static_cast<float>(hy);
  p.z_min = static_cast<float>(z0);
  p.z_max = static_cast<float>(z1);
  p.remission = static_cast<float>(remission);
  return p;
}

Primitive WorldBuilder::cylinder(std::uint16_t label, const Eigen::Vector2d& c, double radius, double z0, double z1,
                                 double remission) {
  Primitive p;
  p.shape = Shape::kCylinder;
  p.label = label;
  p.center = c.cast<float>();
  p.half_x = static_cast<float>(radius);
  p.z_min = static_cast<float>(z0);
  p.z_max = static_cast<float>(z1);
  p.remission = static_cast<float>(remission);
  return p;
}

bool WorldBuilder::far_from(const PointSet& set, const Eigen::Vector2d& c, double min_dist) {
  const auto cx = static_cast<std::int64_t>(std::floor(c.x() / PointSet::kCell));
  const auto cy = static_cast<std::int64_t>(std::floor(c.y() / PointSet::kCell));
  for (std::int64_t dy = -1; dy <= 1; ++dy) {
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      const auto it = set.cells.find(PointSet::key(cx + dx, cy + dy));
      if (it == set.cells.end()) continue;
      for (const auto& p : it->second) {
        if ((p - c).squaredNorm() < min_dist * min_dist) return false;
      }
    }
  }
  return true;
}

void WorldBuilder::build_grid() {
  const double cell = w_.options_.object_cell;
  w_.gx_ = static_cast<int>(std::ceil(w_.nx_ * w_.options_.ground_cell / cell));
  w_.gy_ = static_cast<int>(std::ceil(w_.ny_ * w_.options_.ground_cell / cell));
  const std::size_t n = static_cast<std::size_t>(w_.gx_) * static_cast<std::size_t>(w_.gy_);
  std::vector<std::uint32_t> count(n + 1, 0);
  auto cells = [&](const Primitive& p, auto&& f) {
    const double r = p.footprint_radius();
    const int x0 = std::max(0, static_cast<int>((p.center.x() - r - w_.origin_.x()) / cell));
    const int x1 = std::min(w_.gx_ - 1, static_cast<int>((p.center.x() + r - w_.origin_.x()) / cell));
    const int y0 = std::max(0, static_cast<int>((p.center.y() - r - w_.origin_.y()) / cell));
    const int y1 = std::min(w_.gy_ - 1, static_cast<int>((p.center.y() + r - w_.origin_.y()) / cell));
    for (int iy = y0; iy <= y1; ++iy) {
      for (int ix = x0; ix <= x1; ++ix) f(static_cast<std::size_t>(iy) * static_cast<std::size_t>(w_.gx_) + static_cast<std::size_t>(ix));
    }
  };
  for (const auto& p : w_.primitives_) cells(p, [&](std::size_t c) { ++count[c + 1]; });
  for (std::size_t i = 1; i <= n; ++i) count[i] += count[i - 1];
  w_.cell_start_ = count;
  w_.cell_items_.assign(count[n], 0);
  std::vector<std::uint32_t> fill(count.begin(), count.end() - 1);
  for (std::size_t k = 0; k < w_.primitives_.size(); ++k) {
    cells(w_.primitives_[k], [&](std::size_t c) { w_.cell_items_[fill[c]++] = static_cast<std::uint32_t>(k); });
  }
}

}  // namespace saloam
