// The street world's construction (see world_builder.hpp for its parts):
// the order of the steps and the placement helpers every part uses.

#include <algorithm>
#include <cmath>
#include <utility>

#include "saloam/core/error.hpp"
#include "saloam/sim/world_builder.hpp"

namespace saloam {

using namespace world_building;

World build_world(const std::vector<Pose>& lidar_trajectory, std::uint64_t seed, const WorldOptions& options) {
  if (lidar_trajectory.empty()) throw ConfigError("cannot build a world along an empty trajectory");
  WorldBuilder builder(options, seed);
  builder.build_path(lidar_trajectory);
  builder.build_ground();
  World world = builder.take_world();
  builder.place_objects(world, static_cast<double>(lidar_trajectory.size() - 1) * options.frame_period);
  world.index_objects();
  return world;
}

World WorldBuilder::take_world() {
  origin_ = ground_.origin;
  nx_ = ground_.nx;
  ny_ = ground_.ny;
  return World(options_, seed_, std::move(path_), std::move(ground_));
}

void WorldBuilder::place_objects(World& world, double total_time) {
  w_ = &world;
  place_buildings(total_time);
  place_parked_vehicles(total_time);
  place_street_furniture();
  place_boundaries();
  place_trees();
  place_structures();
  plant_verges();
  place_agents(total_time);
}

double WorldBuilder::street_edge(const Eigen::Vector2d& p, int side) const {
  const World::Zone z = w_->zone_at(p.x(), p.y());
  return z.road(side) + z.parking + z.sidewalk;
}

bool WorldBuilder::inside_grid(const Eigen::Vector2d& p) const {
  return p.x() > origin_.x() + 1 && p.y() > origin_.y() + 1 &&
         p.x() < origin_.x() + (nx_ - 1) * options_.ground_cell &&
         p.y() < origin_.y() + (ny_ - 1) * options_.ground_cell;
}

bool WorldBuilder::rect_free(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy, double clearance,
                             bool road_only) const {
  return for_rect(c, axis, hx, hy, [&](const Eigen::Vector2d& p) {
    if (!inside_grid(p)) return false;
    const World::Zone z = w_->zone_at(p.x(), p.y());
    // Off the street: a margin from the road even where there is no sidewalk.
    const double limit = road_only ? clearance : std::max(z.parking + z.sidewalk + clearance, kRoadsideMargin);
    return w_->road_margin(p.x(), p.y()) >= limit && occupied_[w_->cell_index(p.x(), p.y())] == 0;
  });
}

void WorldBuilder::mark_rect(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy) {
  if (run_marks_) {
    run_marks_->push_back({c, axis, hx, hy});
    return;
  }
  for_rect(c, axis, hx, hy, [&](const Eigen::Vector2d& p) {
    if (inside_grid(p)) occupied_[w_->cell_index(p.x(), p.y())] = 1;
    return true;
  });
}

bool WorldBuilder::clear_of_road(const Eigen::Vector2d& c, double r, double clearance) const {
  return for_rect(c, {1, 0}, r, r, [&](const Eigen::Vector2d& p) {
    return inside_grid(p) && w_->road_margin(p.x(), p.y()) >= clearance;
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

}  // namespace saloam
