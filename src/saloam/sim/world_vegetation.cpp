// Vegetation (see world_builder.hpp): trees and bushes along the street and
// scattered further out, shrub patches on open ground, beds on the bare
// verges; and the tree, bush and shrub-patch primitives.

#include <algorithm>
#include <cmath>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/sim/world_builder.hpp"

namespace saloam {

using namespace world_building;

// Trees after hedges and fences: crowns may overhang them (and gardens),
// only the trunk needs free ground; no crown reaches over the road.
void WorldBuilder::place_trees() {
  place_street_trees();
  scatter_trees();
}

// Tree rows along the verge, bushes between them.
void WorldBuilder::place_street_trees() {
  for (int side = -1; side <= 1; side += 2) {
    Rng rng(hash3(seed_, kSaltTrees, static_cast<std::uint64_t>(side + 5)));
    walk(rng.uniform(0, 10), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
      const Eigen::Vector2d left(-dir.y(), dir.x());
      const Eigen::Vector2d probe = p + side * left * 7.0;
      const World::Zone z = w_->zone_at(probe.x(), probe.y());
      const double edge = z.road(side) + z.parking + z.sidewalk;
      const bool rural = z.sidewalk == 0;
      // Tree rows along the verge; rural land gets more and bigger trees, further out too.
      const double offset = edge + rng.uniform(1.0, rural ? 12.0 : 3.0);
      const Eigen::Vector2d c = p + side * left * offset;
      const double crown = std::min(rng.uniform(2.5, rural ? 5.5 : 5.0), offset - z.road(side) - 0.6);
      if (crown < 1.0 || !far_from(trees_, c, 5.0) || !clear_of_road(c, crown, 0.5) || !disc_free(c, 0.6, 0.3)) {
        return 2.0;
      }
      if (rng.chance(rural ? 0.8 : 0.65)) {
        add_tree(c, crown, rng);
      } else {
        add_bush(c, rng.uniform(0.8, 1.8), rng);
      }
      trees_.push_back(c);
      mark_rect(c, dir, 0.6, 0.6);
      return rng.uniform(3, rural ? 8 : 7);
    });
  }
}

// Scattered trees and bushes further from the street (parks, fields, yards).
void WorldBuilder::scatter_trees() {
  Rng rng(hash_combine(seed_, kSaltTrees + 50));
  walk(0.0, [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
    const Eigen::Vector2d left(-dir.y(), dir.x());
    const bool rural_here = w_->zone_at(p.x(), p.y()).sidewalk == 0;
    for (int k = 0; k < (rural_here ? 90 : 70); ++k) {
      const int side = rng.chance(0.5) ? -1 : 1;
      const Eigen::Vector2d c = p + side * left * rng.uniform(5, 60) + dir * rng.uniform(-5, 5);
      if (!inside_grid(c)) continue;
      const World::Zone zc = w_->zone_at(c.x(), c.y());
      if (w_->road_margin(c.x(), c.y()) < zc.parking + zc.sidewalk + 2) continue;
      const double pick = rng.uniform();
      if (pick < 0.55) {  // shrubs and tall weeds covering part of the grass
        const double rx = rng.uniform(2.0, 6.0), ry = rx * rng.uniform(0.5, 1.0);
        const double yaw = rng.uniform(0, kPi);
        const Eigen::Vector2d axis(std::cos(yaw), std::sin(yaw));
        if (!rect_free(c, axis, rx, ry, 0.8, false)) continue;
        add_shrub_patch(c, axis, rx, ry, rng.uniform(0.8, 2.2), rng);
        mark_rect(c, axis, rx, ry);
        continue;
      }
      const double crown = rng.uniform(2.0, 5.0);
      if (!far_from(trees_, c, 4.0) || !clear_of_road(c, crown, 0.8) || !disc_free(c, 0.8, 0.8)) continue;
      if (pick < 0.8) add_tree(c, crown, rng); else add_bush(c, rng.uniform(0.8, 2.2), rng);
      trees_.push_back(c);
      mark_rect(c, {1, 0}, 0.8, 0.8);
    }
    return 6.0;
  });
}

// Shrub beds and low hedges on whatever verge is still bare behind the
// sidewalk (or the rural road's edge) once plots, fences and trees are
// placed: KITTI's streets are lined with planting, and SemanticKITTI has
// 3.4 times as many vegetation points as terrain points (26.7 % vs 7.8 %).
// Driveways and paths leave about one bed in six out.
void WorldBuilder::plant_verges() {
  for (int side = -1; side <= 1; side += 2) {
    Rng rng(hash3(seed_, kSaltVerges, static_cast<std::uint64_t>(side + 5)));
    walk(rng.uniform(0, 3), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
      const Eigen::Vector2d left(-dir.y(), dir.x());
      const double half_length = rng.uniform(0.8, 1.6);
      if (rng.chance(0.1)) return 2 * half_length + rng.uniform(1.0, 4.0);
      const double half_w = rng.uniform(0.4, 1.2);
      const Eigen::Vector2d probe = p + side * left * 7.0;
      const double edge = street_edge(probe, side);
      const bool rural = w_->zone_at(probe.x(), probe.y()).sidewalk == 0;
      const double gap = line_gap(rural);
      const Eigen::Vector2d c = p + half_length * dir + side * left * (edge + gap + half_w);
      if (!rect_free(c, dir, half_length, half_w, kLineClearance, false)) return 0.5;
      const double g = ground(c);
      const double height = 0.5 + 1.3 * noise_at(hash_combine(seed_, kSaltVerges), c.x(), c.y(), 12.0) + rng.uniform(0.0, 0.3);
      Primitive bed = box(cls::kVegetation, c, dir, half_length, half_w, g - 0.1, g + height, rng.uniform(0.35, 0.5));
      bed.mean_free_path = static_cast<float>(rng.uniform(0.25, 0.5));
      w_->add_object(bed);
      mark_rect(c, dir, half_length, half_w);
      return 2 * half_length;
    });
  }
}

void WorldBuilder::add_tree(const Eigen::Vector2d& c, double crown, Rng& rng) {
  const double g = ground(c);
  // Crowns from 1.2-2.4 m up, as on KITTI's street and garden trees (maples,
  // limes, fruit trees): the near-horizontal beams meet the foliage.
  const double trunk_h = rng.uniform(1.2, 2.4);
  const double radius = rng.uniform(0.1, 0.25);
  w_->add_object(cylinder(cls::kTrunk, c, radius, g, g + trunk_h + crown * 0.8, rng.uniform(0.25, 0.4)));
  const double rz = crown * rng.uniform(0.8, 1.4);
  Primitive leaves;
  leaves.shape = Shape::kEllipsoid;
  leaves.label = cls::kVegetation;
  leaves.center = c.cast<float>();
  leaves.half_x = static_cast<float>(crown);
  leaves.half_y = static_cast<float>(crown * rng.uniform(0.85, 1.0));
  const double yaw = rng.uniform(0, kPi);
  leaves.cos_yaw = static_cast<float>(std::cos(yaw));
  leaves.sin_yaw = static_cast<float>(std::sin(yaw));
  leaves.z_min = static_cast<float>(g + trunk_h);
  leaves.z_max = static_cast<float>(g + trunk_h + 2 * rz);
  leaves.remission = static_cast<float>(rng.uniform(0.35, 0.55));
  leaves.mean_free_path = static_cast<float>(rng.uniform(0.4, 0.9));
  w_->add_object(leaves);
}

void WorldBuilder::add_shrub_patch(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double rx, double ry, double height, Rng& rng) {
  const double g = ground(c);
  Primitive b;
  b.shape = Shape::kEllipsoid;
  b.label = cls::kVegetation;
  b.center = c.cast<float>();
  b.cos_yaw = static_cast<float>(axis.x());
  b.sin_yaw = static_cast<float>(axis.y());
  b.half_x = static_cast<float>(rx);
  b.half_y = static_cast<float>(ry);
  b.z_min = static_cast<float>(g - height);
  b.z_max = static_cast<float>(g + height);
  b.remission = static_cast<float>(rng.uniform(0.35, 0.55));
  b.mean_free_path = 0.35f;
  w_->add_object(b);
}

void WorldBuilder::add_bush(const Eigen::Vector2d& c, double r, Rng& rng) {
  const double g = ground(c);
  Primitive b;
  b.shape = Shape::kEllipsoid;
  b.label = cls::kVegetation;
  b.center = c.cast<float>();
  b.half_x = static_cast<float>(r);
  b.half_y = static_cast<float>(r * rng.uniform(0.7, 1.0));
  b.z_min = static_cast<float>(g - 0.3 * r);
  b.z_max = static_cast<float>(g + r * rng.uniform(1.0, 1.6));
  b.remission = static_cast<float>(rng.uniform(0.35, 0.55));
  b.mean_free_path = 0.3f;
  w_->add_object(b);
}

}  // namespace saloam
