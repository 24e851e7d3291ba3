// Vehicles, street furniture and structures, and the moving agents (see
// world_builder.hpp): cars parked in lanes, lots and along the curbs (some
// there on one pass only), street lights and signs, bus shelters and low
// walls; oncoming and leading cars and pedestrians.

#include <algorithm>
#include <cmath>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/sim/world_builder.hpp"

namespace saloam {

using namespace world_building;

void WorldBuilder::place_parked_vehicles(double total_time) {
  for (int side = -1; side <= 1; side += 2) {
    Rng rng(hash3(seed_, kSaltCars, static_cast<std::uint64_t>(side + 5)));
    walk(rng.uniform(0, 5), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
      const Eigen::Vector2d left(-dir.y(), dir.x());
      const World::Zone z = w_->zone_at(p.x() + side * left.x() * 6, p.y() + side * left.y() * 6);
      if (z.parking <= 0 && z.curb_parking <= 0) return 3.0;
      const double pick = rng.uniform();
      std::uint16_t label = cls::kCar;
      double length = rng.uniform(3.9, 4.9), width = rng.uniform(1.7, 1.9), height = rng.uniform(1.4, 1.65);
      if (pick > 0.92) {
        label = cls::kTruck;
        length = rng.uniform(6.5, 9);
        width = 2.4;
        height = rng.uniform(3.0, 3.6);
      } else if (pick > 0.84) {
        label = cls::kOtherVehicle;
        length = rng.uniform(5.0, 6.2);
        width = rng.uniform(1.95, 2.1);
        height = rng.uniform(2.1, 2.7);
      }
      const bool lot = z.parking > 5;
      const bool curb = z.parking <= 0;
      if (lot && label == cls::kTruck) label = cls::kCar, length = 4.5, width = 1.8, height = 1.5;
      // Streets with a parking lane are nearly fully parked in KITTI's towns.
      const bool present = rng.chance(lot ? 0.8 : (curb ? kCurbParkedShare : 0.92));
      double advance = lot ? 2.8 : length + rng.uniform(0.5, 1.4);
      if (!present) return advance;
      std::vector<Eigen::Vector2d> spots;
      Eigen::Vector2d axis = dir;
      if (lot) {  // two rows of perpendicular bays
        axis = left;
        spots.push_back(p + side * left * (z.road(side) + 3.2));
        if (rng.chance(0.8)) spots.push_back(p + side * left * (z.road(side) + z.parking - 3.2));
      } else if (curb) {
        spots.push_back(p + side * left * (z.road(side) - 0.5 * z.curb_parking));
      } else {
        spots.push_back(p + side * left * (z.road(side) + 0.5 * z.parking + 0.1));
      }
      for (const auto& c : spots) {
        const double hx = 0.5 * length + 0.15, hy = 0.5 * width + 0.1;
        // Off the road, or (at the curb) within the parking strip.
        if (!rect_free(c, axis, hx, curb ? 0.5 * width : hy, curb ? -z.curb_parking - 0.05 : 0.15, true)) continue;
        add_vehicle(c, axis * (rng.chance(0.5) ? 1.0 : -1.0), label, length, width, height, rng, total_time);
        mark_rect(c, axis, hx, hy);
      }
      return advance;
    });
  }
}

void WorldBuilder::add_vehicle(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, std::uint16_t label, double length,
                               double width, double height, Rng& rng, double total_time) {
  const double g = ground(c);
  const std::uint16_t inst = next_instance_++;
  const double rem = rng.uniform(0.08, 0.6);
  Primitive body = box(label, c, axis, 0.5 * length, 0.5 * width, g + 0.25, g + (label == cls::kCar ? 0.55 : 0.75) * height, rem);
  body.instance = inst;
  Primitive cabin = box(label, c - (label == cls::kTruck ? -0.3 : 0.08) * length * axis, axis,
                        (label == cls::kTruck ? 0.18 : 0.3) * length, 0.46 * width, body.z_max, g + height, rem * 0.7);
  cabin.instance = inst;
  if (label == cls::kTruck) {  // cargo box behind the cab
    body.z_max = static_cast<float>(g + height);
    body.half_x = static_cast<float>(0.33 * length);
    body.center = (c - 0.17 * length * axis).cast<float>();
    cabin.z_min = static_cast<float>(g + 0.4);
    cabin.z_max = static_cast<float>(g + 0.8 * height);
    cabin.center = (c + 0.35 * length * axis).cast<float>();
    cabin.half_x = static_cast<float>(0.14 * length);
  }
  // Some parked vehicles are there on one pass and gone on another.
  if (rng.chance(0.35) && total_time > 0) {
    const float t_switch = static_cast<float>(rng.uniform(0, total_time));
    if (rng.chance(0.5)) {
      body.time_off = cabin.time_off = t_switch;
    } else {
      body.time_on = cabin.time_on = t_switch;
    }
  }
  w_->add_object(body);
  w_->add_object(cabin);
}

void WorldBuilder::place_street_furniture() {
  // Street lights and signs near the curb, trees in the verge.
  for (int side = -1; side <= 1; side += 2) {
    Rng rng(hash3(seed_, kSaltPoles, static_cast<std::uint64_t>(side + 5)));
    walk(rng.uniform(0, 20), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
      const Eigen::Vector2d left(-dir.y(), dir.x());
      const World::Zone z = w_->zone_at(p.x() + side * left.x() * 6, p.y() + side * left.y() * 6);
      const double off = z.road(side) + z.parking + (z.sidewalk > 0 ? 0.45 : 1.2);
      const Eigen::Vector2d c = p + side * left * off;
      if (!far_from(poles_, c, 9.0) || !disc_free(c, 0.3, 0.25)) return 3.0;
      const double g = ground(c);
      if (rng.chance(0.7)) {  // street light with an arm over the road
        // Draws kept in sequence (radius, height, remission): the world must not change.
        const double radius = rng.uniform(0.09, 0.14);
        const double h = rng.uniform(6, 9);
        const Primitive pole = cylinder(cls::kPole, c, radius, g, g + h, rng.uniform(0.25, 0.45));
        w_->add_object(pole);
        const Eigen::Vector2d arm_c = c - side * left * 0.9;
        w_->add_object(box(cls::kPole, arm_c, left, 0.9, 0.07, g + h - 0.15, g + h, pole.remission));
      } else {  // traffic sign on a thin post, the plate facing traffic
        const double radius = rng.uniform(0.04, 0.06);
        const double h = rng.uniform(2.0, 2.8);
        w_->add_object(cylinder(cls::kPole, c, radius, g, g + h, 0.35));
        const double plate = rng.uniform(0.3, 0.45);
        Primitive sign = box(cls::kTrafficSign, c, dir, 0.025, plate, g + h, g + h + 2 * plate, rng.uniform(0.75, 0.95));
        w_->add_object(sign);
      }
      poles_.push_back(c);
      mark_rect(c, dir, 0.3, 0.3);
      return rng.uniform(10, 26);
    });
  }
}

void WorldBuilder::place_structures() {
  Rng rng(hash_combine(seed_, kSaltStructures));
  walk(rng.uniform(30, 120), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
    const int side = rng.chance(0.5) ? -1 : 1;
    const Eigen::Vector2d left(-dir.y(), dir.x());
    const double edge = street_edge(p + side * left * 7.0, side);
    const Eigen::Vector2d c = p + side * left * (edge + 1.2);
    const double g = ground(c);
    if (rng.chance(0.5)) {  // bus shelter / kiosk
      if (!rect_free(c, dir, 2.0, 1.0, 0.1, false)) return 10.0;
      Primitive shelter = box(cls::kOtherStructure, c, dir, 1.8, 0.8, g + 2.1, g + 2.4, 0.3);
      w_->add_object(shelter);
      w_->add_object(box(cls::kOtherStructure, c + side * left * 0.75, dir, 1.8, 0.05, g, g + 2.1, 0.5));
      mark_rect(c, dir, 2.0, 1.0);
    } else {  // low wall
      const double half = rng.uniform(3, 10);
      if (!rect_free(c, dir, half, 0.3, 0.1, false)) return 10.0;
      w_->add_object(box(cls::kOtherStructure, c, dir, half, 0.15, g - 0.1, g + rng.uniform(0.5, 1.2), 0.35));
      mark_rect(c, dir, half, 0.3);
    }
    return rng.uniform(120, 300);
  });
}

void WorldBuilder::place_agents(double total_time) {
  if (!options_.dynamic_objects) return;
  Rng rng(hash_combine(seed_, kSaltAgents));
  std::uint16_t inst = 1000;
  // Oncoming cars in the left lane, each meeting the ego at some time.
  for (double t = rng.uniform(1, 5); t < total_time; t += rng.uniform(4, 11)) {
    Agent a;
    a.label = cls::kMovingCar;
    a.instance = inst++;
    a.t_ref = t;
    a.s_ref = w_->ego_arc_length(t);
    a.speed = -rng.uniform(7, 13);
    a.lateral = rng.uniform(2.9, 3.2);  // the oncoming lane, clear of cars parked at its curb
    a.t_begin = t - 15;
    a.t_end = t + 15;
    vehicle_dims(a, rng);
    w_->add_agent(a);
  }
  // A car ahead in the ego lane, now and then, plus one that overtakes on the left rarely.
  for (double t = rng.uniform(0, 10); t < total_time; t += rng.uniform(30, 70)) {
    Agent a;
    a.motion = Agent::Motion::kLeadsEgo;
    a.label = cls::kMovingCar;
    a.instance = inst++;
    a.gap = rng.uniform(14, 30);
    a.gap_amplitude = rng.uniform(2, 6);
    a.gap_period = rng.uniform(15, 40);
    a.gap_phase = rng.uniform(0, 2 * kPi);
    a.speed = 1;
    a.t_begin = t;
    a.t_end = t + rng.uniform(15, 35);
    vehicle_dims(a, rng);
    w_->add_agent(a);
  }
  // Pedestrians on the sidewalks, walking either way.
  for (double t = rng.uniform(0, 4); t < total_time; t += rng.uniform(2, 7)) {
    Agent a;
    a.label = cls::kMovingPerson;
    a.instance = inst++;
    a.t_ref = t;
    a.s_ref = w_->ego_arc_length(t) + rng.uniform(-10, 30);
    a.speed = (rng.chance(0.5) ? 1 : -1) * rng.uniform(1.0, 1.6);
    a.sidewalk_side = rng.chance(0.5) ? 1 : -1;
    a.t_begin = t - 25;
    a.t_end = t + 25;
    a.width = static_cast<float>(rng.uniform(0.38, 0.5));
    a.height = static_cast<float>(rng.uniform(1.6, 1.9));
    a.remission = static_cast<float>(rng.uniform(0.15, 0.4));
    a.gap_phase = rng.uniform(0, 2 * kPi);
    w_->add_agent(a);
  }
}

void WorldBuilder::vehicle_dims(Agent& a, Rng& rng) {
  a.length = static_cast<float>(rng.uniform(4.0, 4.9));
  a.width = static_cast<float>(rng.uniform(1.72, 1.9));
  a.height = static_cast<float>(rng.uniform(1.4, 1.65));
  a.remission = static_cast<float>(rng.uniform(0.08, 0.6));
}

}  // namespace saloam
