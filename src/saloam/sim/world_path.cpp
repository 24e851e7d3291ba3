// The world's driven path and ego timeline (arc length, points along the
// path) and its moving agents at a given time; the ground and the ray caster
// are world.cpp.
#include <algorithm>
#include <cmath>
#include <vector>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/sim/world.hpp"

namespace saloam {
namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

double World::ego_arc_length(double t) const {
  if (path_.ego_s.empty()) return 0.0;
  const double f = t / options_.frame_period;
  if (f <= 0) return path_.ego_s.front();
  const auto i = static_cast<std::size_t>(f);
  if (i + 1 >= path_.ego_s.size()) return path_.ego_s.back();
  const double a = f - static_cast<double>(i);
  return path_.ego_s[i] + a * (path_.ego_s[i + 1] - path_.ego_s[i]);
}

void WorldPath::point(double at, Eigen::Vector3d& position, Eigen::Vector2d& direction) const {
  if (points.size() < 2) {
    position = points.empty() ? Eigen::Vector3d::Zero() : points.front();
    direction = {1, 0};
    return;
  }
  at = std::clamp(at, 0.0, s.back());
  auto it = std::upper_bound(s.begin(), s.end(), at);
  std::size_t i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(1, it - s.begin())) - 1;
  i = std::min(i, points.size() - 2);
  const double len = s[i + 1] - s[i];
  const double a = len > 1e-9 ? (at - s[i]) / len : 0.0;
  position = points[i] + a * (points[i + 1] - points[i]);
  // Direction smoothed over a few metres so cars do not jitter at kinks.
  const std::size_t i0 = i >= 3 ? i - 3 : 0, i1 = std::min(points.size() - 1, i + 4);
  direction = (points[i1] - points[i0]).head<2>();
  if (direction.norm() < 1e-9) direction = {1, 0};
  direction.normalize();
}

void World::path_point(double s, Eigen::Vector3d& position, Eigen::Vector2d& direction) const {
  path_.point(s, position, direction);
}

namespace {

/// A walking person at `xy`: body and head, legs swinging with the gait.
/// `body` holds the agent's label, instance, centre, heading and remission.
void add_person(const Agent& a, Primitive body, const Eigen::Vector2d& xy, const Eigen::Vector2d& heading,
                double ground, double t, std::vector<Primitive>& out) {
  body.shape = Shape::kCylinder;
  body.half_x = 0.5f * a.width;
  body.z_min = static_cast<float>(ground + 0.75);
  body.z_max = static_cast<float>(ground + a.height - 0.25);
  out.push_back(body);
  Primitive head = body;
  head.shape = Shape::kEllipsoid;
  head.half_x = head.half_y = 0.11f;
  head.z_min = static_cast<float>(ground + a.height - 0.24);
  head.z_max = static_cast<float>(ground + a.height);
  out.push_back(head);
  const double swing = 0.25 * std::sin(2 * kPi * 1.8 * t + a.gap_phase);
  for (int leg = -1; leg <= 1; leg += 2) {
    Primitive l = body;
    l.half_x = 0.08f;
    l.center = (xy + leg * swing * heading + leg * 0.1 * Eigen::Vector2d(-heading.y(), heading.x())).cast<float>();
    l.z_min = static_cast<float>(ground);
    l.z_max = static_cast<float>(ground + 0.8);
    out.push_back(l);
  }
}

/// A vehicle at `xy`: body, a cabin set back a little, and four wheels below the body.
void add_vehicle(const Agent& a, Primitive body, const Eigen::Vector2d& xy, const Eigen::Vector2d& heading,
                 double ground, std::vector<Primitive>& out) {
  body.shape = Shape::kBox;
  body.half_x = 0.5f * a.length;
  body.half_y = 0.5f * a.width;
  body.z_min = static_cast<float>(ground + 0.3);
  body.z_max = static_cast<float>(ground + 0.55 * a.height);
  out.push_back(body);
  Primitive cabin = body;  // greenhouse
  cabin.half_x = 0.28f * a.length;
  cabin.half_y = 0.45f * a.width;
  cabin.center = (xy - 0.08 * a.length * heading).cast<float>();
  cabin.z_min = body.z_max;
  cabin.z_max = static_cast<float>(ground + a.height);
  out.push_back(cabin);
  for (int w = 0; w < 4; ++w) {
    Primitive wheel = body;
    wheel.shape = Shape::kBox;
    wheel.half_x = 0.32f;
    wheel.half_y = 0.12f;
    const double fx = (w < 2 ? 0.33 : -0.33) * a.length, fy = (w % 2 == 0 ? 0.42 : -0.42) * a.width;
    wheel.center = (xy + fx * heading + fy * Eigen::Vector2d(-heading.y(), heading.x())).cast<float>();
    wheel.z_min = static_cast<float>(ground);
    wheel.z_max = static_cast<float>(ground + 0.3);
    wheel.remission = 0.08f;
    out.push_back(wheel);
  }
}

}  // namespace

bool World::agent_place(const Agent& a, double t, Eigen::Vector2d& xy, Eigen::Vector2d& direction) const {
  if (t < a.t_begin || t >= a.t_end) return false;
  double s = 0;
  if (a.motion == Agent::Motion::kLeadsEgo) {
    s = ego_arc_length(t) + a.gap + a.gap_amplitude * std::sin(2 * kPi * t / a.gap_period + a.gap_phase);
  } else {
    s = a.s_ref + a.speed * (t - a.t_ref);
  }
  if (s < 0 || s > path_length()) return false;
  Eigen::Vector3d pos;
  path_point(s, pos, direction);
  const Eigen::Vector2d left(-direction.y(), direction.x());
  double lateral = a.lateral;
  if (a.sidewalk_side != 0) {
    // Rural roads have no sidewalk: walk on the verge beside the road.
    const Zone z = zone_at(pos.x(), pos.y());
    lateral = a.sidewalk_side * (z.road(a.sidewalk_side) + z.parking + (z.sidewalk > 0 ? 0.5 * z.sidewalk : 1.2));
  }
  xy = pos.head<2>() + lateral * left;
  return true;
}

void World::agents_at(double t, const Eigen::Vector2d& near, double radius, std::vector<Primitive>& out) const {
  out.clear();
  for (const Agent& a : agents_) {
    Eigen::Vector2d xy, dir;
    if (!agent_place(a, t, xy, dir) || (xy - near).norm() > radius) continue;
    const Eigen::Vector2d heading = a.speed < 0 ? Eigen::Vector2d(-dir) : dir;
    Primitive p;
    p.label = a.label;
    p.instance = a.instance;
    p.center = xy.cast<float>();
    p.cos_yaw = static_cast<float>(heading.x());
    p.sin_yaw = static_cast<float>(heading.y());
    p.remission = a.remission;
    const double ground = ground_height(xy.x(), xy.y());
    if (a.label == cls::kMovingPerson) {
      add_person(a, p, xy, heading, ground, t, out);
    } else {
      add_vehicle(a, p, xy, heading, ground, out);
    }
  }
}

}  // namespace saloam
