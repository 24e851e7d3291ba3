#include "saloam/sim/world.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "saloam/core/error.hpp"
#include "saloam/core/semantic_classes.hpp"

namespace saloam {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// How far the sensor may sit below / above its nominal height over the ground
// (suspension, load, a curb under one wheel, the smoothing of the ground).
constexpr double kSensorClearanceBelow = 0.5;
constexpr double kSensorClearanceAbove = 0.8;

struct Interval {
  double t0 = kInf, t1 = -kInf;
  Eigen::Vector3d normal{0, 0, 1};
  int face = -1;  // box: 0/1 = local x faces, 2/3 = local y faces, 4 = top/bottom
  double u = 0;   // box face coordinate along the face (for facades)
};

// Ray against a vertical box in its local frame. Returns entry/exit.
bool intersect_box(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d, Interval& out) {
  const double px = o.x() - p.center.x(), py = o.y() - p.center.y();
  const double c = p.cos_yaw, s = p.sin_yaw;
  const double lx = c * px + s * py, ly = -s * px + c * py;
  const double dx = c * d.x() + s * d.y(), dy = -s * d.x() + c * d.y();
  double t0 = -kInf, t1 = kInf;
  int face = -1;
  auto slab = [&](double pos, double dir, double lo, double hi, int face_lo) {
    if (std::abs(dir) < 1e-12) return pos >= lo && pos <= hi;
    double a = (lo - pos) / dir, b = (hi - pos) / dir;
    int f = face_lo;
    if (a > b) {
      std::swap(a, b);
      f = face_lo + 1;
    }
    if (a > t0) {
      t0 = a;
      face = f;
    }
    t1 = std::min(t1, b);
    return t0 <= t1;
  };
  if (!slab(lx, dx, -p.half_x, p.half_x, 0)) return false;
  if (!slab(ly, dy, -p.half_y, p.half_y, 2)) return false;
  if (!slab(o.z(), d.z(), p.z_min, p.z_max, 4)) return false;
  if (t1 < 0 || t0 < 0) return false;  // behind, or the origin is inside
  out.t0 = t0;
  out.t1 = t1;
  out.face = face;
  Eigen::Vector2d n_local(0, 0);
  const double hx = lx + t0 * dx, hy = ly + t0 * dy;
  switch (face) {
    case 0: n_local = {-1, 0}; out.u = hy; break;
    case 1: n_local = {1, 0}; out.u = hy; break;
    case 2: n_local = {0, -1}; out.u = hx; break;
    case 3: n_local = {0, 1}; out.u = hx; break;
    default: break;
  }
  if (face >= 4) {
    out.normal = {0, 0, face == 4 ? -1.0 : 1.0};
  } else {
    out.normal = {c * n_local.x() - s * n_local.y(), s * n_local.x() + c * n_local.y(), 0};
  }
  return true;
}

bool intersect_cylinder(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d, Interval& out) {
  const double px = o.x() - p.center.x(), py = o.y() - p.center.y();
  const double r = p.half_x;
  const double a = d.x() * d.x() + d.y() * d.y();
  double t0, t1;
  if (a < 1e-12) {
    if (px * px + py * py > r * r) return false;
    t0 = -kInf;
    t1 = kInf;
  } else {
    const double b = px * d.x() + py * d.y();
    const double cc = px * px + py * py - r * r;
    const double disc = b * b - a * cc;
    if (disc < 0) return false;
    const double sq = std::sqrt(disc);
    t0 = (-b - sq) / a;
    t1 = (-b + sq) / a;
  }
  Eigen::Vector3d normal;
  const double zt0 = o.z() + t0 * d.z();
  if (zt0 >= p.z_min && zt0 <= p.z_max) {
    normal = Eigen::Vector3d(px + t0 * d.x(), py + t0 * d.y(), 0).normalized();
  } else {
    // Enter through a cap (or miss).
    if (std::abs(d.z()) < 1e-12) return false;
    const double cap = zt0 > p.z_max ? p.z_max : p.z_min;
    const double tc = (cap - o.z()) / d.z();
    if (tc < t0 || tc > t1) return false;
    t0 = tc;
    normal = {0, 0, zt0 > p.z_max ? 1.0 : -1.0};
  }
  if (t0 < 0) return false;
  out.t0 = t0;
  out.t1 = t1;
  out.normal = normal;
  return true;
}

bool intersect_ellipsoid(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d, Interval& out) {
  const double cz = 0.5 * (p.z_min + p.z_max), rz = 0.5 * (p.z_max - p.z_min);
  const double px = o.x() - p.center.x(), py = o.y() - p.center.y();
  const double c = p.cos_yaw, s = p.sin_yaw;
  const Eigen::Vector3d lo((c * px + s * py) / p.half_x, (-s * px + c * py) / p.half_y, (o.z() - cz) / rz);
  const Eigen::Vector3d ld((c * d.x() + s * d.y()) / p.half_x, (-s * d.x() + c * d.y()) / p.half_y, d.z() / rz);
  const double a = ld.squaredNorm(), b = lo.dot(ld), cc = lo.squaredNorm() - 1.0;
  const double disc = b * b - a * cc;
  if (disc < 0) return false;
  const double sq = std::sqrt(disc);
  const double t0 = (-b - sq) / a, t1 = (-b + sq) / a;
  if (t0 < 0) return false;
  out.t0 = t0;
  out.t1 = t1;
  const Eigen::Vector3d q = lo + t0 * ld;
  const Eigen::Vector3d nl(q.x() / p.half_x, q.y() / p.half_y, q.z() / rz);
  out.normal = Eigen::Vector3d(c * nl.x() - s * nl.y(), s * nl.x() + c * nl.y(), nl.z()).normalized();
  return true;
}

bool intersect(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d, Interval& out) {
  switch (p.shape) {
    case Shape::kBox: return intersect_box(p, o, d, out);
    case Shape::kCylinder: return intersect_cylinder(p, o, d, out);
    case Shape::kEllipsoid: return intersect_ellipsoid(p, o, d, out);
  }
  return false;
}

// Resolves the actual return inside an interval: porous media, facades.
// Returns the range or +inf when the ray passes (or the glass eats it).
double surface_range(const Primitive& p, const Interval& iv, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                     Rng& rng) {
  if (p.mean_free_path > 0) {
    const double depth = rng.exponential(p.mean_free_path);
    return iv.t0 + depth < iv.t1 ? iv.t0 + depth : kInf;
  }
  const FacadePattern& f = p.facade;
  if (f.floor_height > 0 && iv.face >= 0 && iv.face < 4) {
    const double z = o.z() + iv.t0 * d.z() - p.z_min;
    const double floor_pos = std::fmod(z, static_cast<double>(f.floor_height));
    const double u = iv.u + 1000.0;  // keep fmod's argument positive
    const double u_pos = std::fmod(u, static_cast<double>(f.window_spacing));
    const double sill = 0.5 * (f.floor_height - f.window_height);
    const bool window = z > 1.0 && z < p.z_max - p.z_min - 0.8 && floor_pos > sill &&
                        floor_pos < sill + f.window_height && u_pos < f.window_width;
    if (window) {
      if (rng.chance(f.glass_dropout)) return -kInf;  // glass: no return at all
      const double cos_inc = std::max(0.2, std::abs(iv.normal.dot(d)));
      return iv.t0 + f.recess / cos_inc;
    }
  }
  return iv.t0;
}

}  // namespace

float Primitive::footprint_radius() const {
  if (shape == Shape::kCylinder) return half_x;
  if (shape == Shape::kEllipsoid) return std::max(half_x, half_y);
  return std::hypot(half_x, half_y);
}

// ---------------------------------------------------------------- construction

World::World(const WorldOptions& options, std::uint64_t seed, WorldPath path, Ground ground)
    : options_(options), seed_(seed), path_(std::move(path)), ground_(std::move(ground)) {
  const std::size_t n = ground_.distance.size();
  packed_.resize(n);
  for (std::size_t i = 0; i < n; ++i) packed_[i] = {ground_.distance[i], ground_.height[i], ground_.bump[i], 0.0f};
}

void World::index_objects() {
  const double cell = options_.object_cell;
  gx_ = static_cast<int>(std::ceil(ground_.nx * options_.ground_cell / cell));
  gy_ = static_cast<int>(std::ceil(ground_.ny * options_.ground_cell / cell));
  const std::size_t n = static_cast<std::size_t>(gx_) * static_cast<std::size_t>(gy_);
  std::vector<std::uint32_t> count(n + 1, 0);
  auto cells = [&](const Primitive& p, auto&& f) {
    const double r = p.footprint_radius();
    const int x0 = std::max(0, static_cast<int>((p.center.x() - r - ground_.origin.x()) / cell));
    const int x1 = std::min(gx_ - 1, static_cast<int>((p.center.x() + r - ground_.origin.x()) / cell));
    const int y0 = std::max(0, static_cast<int>((p.center.y() - r - ground_.origin.y()) / cell));
    const int y1 = std::min(gy_ - 1, static_cast<int>((p.center.y() + r - ground_.origin.y()) / cell));
    for (int iy = y0; iy <= y1; ++iy) {
      for (int ix = x0; ix <= x1; ++ix) f(static_cast<std::size_t>(iy) * static_cast<std::size_t>(gx_) + static_cast<std::size_t>(ix));
    }
  };
  for (const auto& p : primitives_) cells(p, [&](std::size_t c) { ++count[c + 1]; });
  for (std::size_t i = 1; i <= n; ++i) count[i] += count[i - 1];
  cell_start_ = count;
  cell_items_.assign(count[n], 0);
  std::vector<std::uint32_t> fill(count.begin(), count.end() - 1);
  for (std::size_t k = 0; k < primitives_.size(); ++k) {
    cells(primitives_[k], [&](std::size_t c) { cell_items_[fill[c]++] = static_cast<std::uint32_t>(k); });
  }
}

// ---------------------------------------------------------------- ground

std::size_t World::cell_index(double x, double y) const {
  const int ix = std::clamp(static_cast<int>((x - ground_.origin.x()) / options_.ground_cell), 0, ground_.nx - 1);
  const int iy = std::clamp(static_cast<int>((y - ground_.origin.y()) / options_.ground_cell), 0, ground_.ny - 1);
  return static_cast<std::size_t>(iy) * static_cast<std::size_t>(ground_.nx) + static_cast<std::size_t>(ix);
}

double World::bilinear(const std::vector<float>& field, double x, double y) const {
  const double gx = (x - ground_.origin.x()) / options_.ground_cell - 0.5;
  const double gy = (y - ground_.origin.y()) / options_.ground_cell - 0.5;
  const double fx = std::clamp(gx, 0.0, ground_.nx - 1.001), fy = std::clamp(gy, 0.0, ground_.ny - 1.001);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const double tx = fx - ix, ty = fy - iy;
  const std::size_t i = static_cast<std::size_t>(iy) * static_cast<std::size_t>(ground_.nx) + static_cast<std::size_t>(ix);
  const double a = field[i], b = field[i + 1];
  const double c = field[i + static_cast<std::size_t>(ground_.nx)], e = field[i + static_cast<std::size_t>(ground_.nx) + 1];
  return (a + (b - a) * tx) * (1 - ty) + (c + (e - c) * tx) * ty;
}

double World::path_distance(double x, double y) const { return bilinear(ground_.distance, x, y); }

World::Zone World::zone_at(double x, double y) const { return ground_.zones[cell_index(x, y)]; }

double World::path_lateral(double x, double y) const {
  // The side comes from the nearest cell, the magnitude from the continuous
  // distance field: interpolating the signed field across a Voronoi edge
  // between two centre lines would make a thin false road there.
  const double d = path_distance(x, y);
  return ground_.lateral[cell_index(x, y)] >= 0 ? d : -d;
}

double World::road_margin(double x, double y) const {
  const double lat = path_lateral(x, y);
  const Zone z = zone_at(x, y);
  return lat >= 0 ? lat - z.road_left : -lat - z.road_right;
}

World::FieldSample World::sample(double x, double y) const {
  const double inv = 1.0 / options_.ground_cell;
  const double ux = (x - ground_.origin.x()) * inv, uy = (y - ground_.origin.y()) * inv;
  const int cx = std::clamp(static_cast<int>(ux), 0, ground_.nx - 1), cy = std::clamp(static_cast<int>(uy), 0, ground_.ny - 1);
  const double fx = std::clamp(ux - 0.5, 0.0, ground_.nx - 1.001), fy = std::clamp(uy - 0.5, 0.0, ground_.ny - 1.001);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const double tx = fx - ix, ty = fy - iy;
  const std::size_t i = static_cast<std::size_t>(iy) * static_cast<std::size_t>(ground_.nx) + static_cast<std::size_t>(ix);
  const PackedCell& a = packed_[i];
  const PackedCell& b = packed_[i + 1];
  const PackedCell& c = packed_[i + static_cast<std::size_t>(ground_.nx)];
  const PackedCell& e = packed_[i + static_cast<std::size_t>(ground_.nx) + 1];
  const double wa = (1 - tx) * (1 - ty), wb = tx * (1 - ty), wc = (1 - tx) * ty, we = tx * ty;
  return {wa * a.distance + wb * b.distance + wc * c.distance + we * e.distance,
          wa * a.height + wb * b.height + wc * c.height + we * e.height,
          wa * a.bump + wb * b.bump + wc * c.bump + we * e.bump,
          static_cast<std::size_t>(cy) * static_cast<std::size_t>(ground_.nx) + static_cast<std::size_t>(cx)};
}

GroundInfo World::ground_at(double x, double y) const { return ground_from(sample(x, y)); }

GroundInfo World::ground_from(const FieldSample& s) const {
  // Side from the nearest cell, magnitude from the continuous distance (see path_lateral).
  const double lat = ground_.lateral[s.cell] >= 0 ? s.distance : -s.distance;
  const Zone& z = ground_.zones[s.cell];
  const double d = lat >= 0 ? lat - z.road_left : -lat - z.road_right;  // beyond the road edge
  const double base = s.height;
  GroundInfo g;
  const double park = z.parking, walk = park + z.sidewalk;
  if (d < 0.0) {
    g.height = base;
    g.label = cls::kRoad;
    // Lane lines: the centre line left of the ego lane and the road edges.
    const bool marking = (lat > 1.5 && lat < 1.65) || (d > -0.4 && d < -0.25);
    g.remission = marking ? 0.62f : 0.22f;
    return g;
  }
  if (d < park) {
    g.height = base + kParkingRise;
    g.label = cls::kParking;
    g.remission = 0.26f;
    return g;
  }
  const double curb = z.sidewalk > 0 ? kCurbHeight : 0.0;
  if (d < walk) {
    g.height = base + curb;
    g.label = cls::kSidewalk;
    g.remission = 0.3f;
    return g;
  }
  // Verge: gently undulating, rising away from the street.
  const double fade = std::min(1.0, (d - walk) / 12.0);
  g.height = base + curb + fade * s.bump;
  switch (z.verge) {
    case 1: g.label = cls::kSidewalk; g.remission = 0.3f; break;
    case 2: g.label = cls::kOtherGround; g.remission = 0.24f; break;
    default: g.label = cls::kTerrain; g.remission = 0.42f; break;
  }
  return g;
}

double World::ground_height(double x, double y) const { return ground_at(x, y).height; }

Eigen::Vector3d World::sensor_origin(const Eigen::Vector3d& pose_origin) const {
  const double ground = ground_height(pose_origin.x(), pose_origin.y());
  const double z = std::clamp(pose_origin.z(), ground + options_.sensor_height - kSensorClearanceBelow,
                              ground + options_.sensor_height + kSensorClearanceAbove);
  return {pose_origin.x(), pose_origin.y(), z};
}

// The first ground crossing of a ray, found by marching along it with steps
// that grow with range and shrink near the ground, then refining the crossing
// by regula falsi (the ground has curbs: no closed form, but it is nearly
// planar, so few refinements are needed). Lazy: beyond(x) marches only until
// it knows whether the crossing lies beyond x, so a ray that meets an object
// first never marches the ground behind it. The steps and the crossing are
// those of marching the whole way, whatever was asked on the way.
class World::GroundMarch {
 public:
  GroundMarch(const World& world, const RayOrigin& o, const Eigen::Vector3d& d, double max_t)
      : world_(world), o_(o.position), d_(d), d_xy_(std::hypot(d.x(), d.y())), max_t_(max_t), f_prev_(o.clearance) {
    if (f_prev_ <= 0) finish(0.0);
  }

  /// True when the crossing lies beyond range x (or there is none).
  bool beyond(double x) {
    while (!done_ && t_prev_ < x) advance();
    return done_ ? crossing_ > x : true;  // not done: no crossing up to t_prev_ >= x
  }
  /// The crossing's range (infinity when none within max_t), marching to the end.
  double crossing() {
    while (!done_) advance();
    return crossing_;
  }

 private:
  double above(double t) const {
    const Eigen::Vector3d p = o_ + t * d_;
    return p.z() - world_.ground_from(world_.sample(p.x(), p.y())).height;
  }
  void finish(double crossing) {
    done_ = true;
    crossing_ = crossing;
  }
  void advance() {
    if (t_prev_ >= max_t_) return finish(kInf);
    t_ = std::min(t_, max_t_);
    const double f = above(t_);
    if (f <= 0) return finish(refine(f));
    // Rays going up and well above the ground never come back.
    if (d_.z() > 0.0 && f > 2.5) return finish(kInf);
    t_prev_ = t_;
    f_prev_ = f;
    double step = std::max(0.2, 0.04 * t_);
    if (d_.z() < -1e-3) step = std::max(step, 0.8 * f / -d_.z());
    step = std::min(step, std::max(0.5, 0.35 * t_));
    t_ = std::max(t_ + std::max(step, clear_step(f)), first_contact());
  }
  // The first range from t_ on where the ray may reach down to the ground:
  // tile by tile along the ray, its height against the highest the ground
  // gets in the tile. Over flat streets and open land that skips every tile
  // up to the one where the ray comes down.
  double first_contact() const {
    const TilePosition here = tile_here();
    const double tile = tile_size();
    int tx = here.x, ty = here.y;
    // Ranges at which the ray leaves the current tile column / row (2D DDA).
    const double dt_x = std::abs(d_.x()) > 1e-12 ? tile / std::abs(d_.x()) : kInf;
    const double dt_y = std::abs(d_.y()) > 1e-12 ? tile / std::abs(d_.y()) : kInf;
    double next_x = t_ + (d_.x() >= 0 ? tx + 1 - here.ux : here.ux - tx) * dt_x;
    double next_y = t_ + (d_.y() >= 0 ? ty + 1 - here.uy : here.uy - ty) * dt_y;
    double t = t_;
    while (t < max_t_ && in_tiles(tx, ty)) {
      const double top = world_.ground_.top[tile_index(tx, ty)];
      const double exit = std::min({next_x, next_y, max_t_});
      const double lowest = o_.z() + (d_.z() < 0.0 ? exit : t) * d_.z();  // the ray's lowest point in the tile
      if (lowest <= top) {
        // It comes down to the tile's top within the tile (or starts below it).
        return d_.z() < 0.0 ? std::max(t, (o_.z() - top) / -d_.z()) : t;
      }
      t = exit;
      if (next_x < next_y) {
        tx += d_.x() >= 0 ? 1 : -1;
        next_x += dt_x;
      } else {
        ty += d_.y() >= 0 ? 1 : -1;
        next_y += dt_y;
      }
    }
    return t;
  }
  // How far the ray surely stays above the ground from its point at t_, f
  // above it, without leaving the current rise tile: the ground rises at
  // most the tile's bound per metre travelled horizontally (plus one step of
  // kGroundStep), while the ray climbs d_z per metre. Rays over open, gently
  // sloping ground then reach it, or leave it, in a few long steps.
  double clear_step(double f) const {
    if (f <= World::kGroundStep) return 0.0;
    const TilePosition here = tile_here();
    const double tile = tile_size();
    const int tx = here.x, ty = here.y;
    if (!in_tiles(tx, ty)) return 0.0;
    const double rise = world_.ground_.rise[tile_index(tx, ty)];
    // Distance along the ray to the tile's edge.
    double exit = max_t_;
    if (std::abs(d_.x()) > 1e-12) exit = std::min(exit, ((d_.x() > 0 ? tx + 1 - here.ux : here.ux - tx) * tile) / std::abs(d_.x()));
    if (std::abs(d_.y()) > 1e-12) exit = std::min(exit, ((d_.y() > 0 ? ty + 1 - here.uy : here.uy - ty) * tile) / std::abs(d_.y()));
    const double closing = rise * d_xy_ - d_.z();
    const double clear = closing > 0.0 ? 0.9 * (f - World::kGroundStep) / closing : max_t_;
    return std::min(clear, exit);
  }
  // The rise tiles (Ground::rise, Ground::top): the ray's
  // point at t_ in tile units and the tile it lies in.
  struct TilePosition {
    double ux, uy;
    int x, y;
  };
  double tile_size() const { return World::kRiseTile * world_.options_.ground_cell; }
  TilePosition tile_here() const {
    const double tile = tile_size();
    const Eigen::Vector3d p = o_ + t_ * d_;
    const double ux = (p.x() - world_.ground_.origin.x()) / tile, uy = (p.y() - world_.ground_.origin.y()) / tile;
    return {ux, uy, static_cast<int>(std::floor(ux)), static_cast<int>(std::floor(uy))};
  }
  bool in_tiles(int x, int y) const { return x >= 0 && y >= 0 && x < world_.ground_.rise_nx && y < world_.ground_.rise_ny; }
  std::size_t tile_index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(world_.ground_.rise_nx) + static_cast<std::size_t>(x);
  }
  // Illinois variant of regula falsi on [t_prev (above), t (below)].
  double refine(double f_below) const {
    double lo = t_prev_, hi = t_, f_lo = f_prev_, f_hi = f_below;
    int side = 0;
    for (int i = 0; i < 20 && hi - lo > 0.003; ++i) {
      const double m = std::clamp(lo + (hi - lo) * f_lo / (f_lo - f_hi), lo + 1e-4, hi - 1e-4);
      const double fm = above(m);
      if (fm > 0) {
        lo = m;
        f_lo = fm;
        if (side == -1) f_hi *= 0.5;
        side = -1;
      } else {
        hi = m;
        f_hi = fm;
        if (side == 1) f_lo *= 0.5;
        side = 1;
      }
    }
    return hi;
  }

  const World& world_;
  const Eigen::Vector3d o_, d_;
  const double d_xy_;  ///< horizontal length of the direction
  const double max_t_;
  double t_prev_ = 0.0, f_prev_, t_ = 1.0;
  bool done_ = false;
  double crossing_ = kInf;
};

namespace {
// A ray's walk through a 2D grid of `cell` metres from `origin` (Amanatides &
// Woo): the cell it is in (ix, iy) and the ray parameter where it leaves it.
struct GridWalk {
  GridWalk(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector2d& origin, double cell) {
    const double gxf = (o.x() - origin.x()) / cell, gyf = (o.y() - origin.y()) / cell;
    ix = static_cast<int>(std::floor(gxf));
    iy = static_cast<int>(std::floor(gyf));
    step_x = d.x() >= 0 ? 1 : -1;
    step_y = d.y() >= 0 ? 1 : -1;
    const double inv_x = std::abs(d.x()) > 1e-12 ? 1.0 / std::abs(d.x()) : kInf;
    const double inv_y = std::abs(d.y()) > 1e-12 ? 1.0 / std::abs(d.y()) : kInf;
    t_max_x = (d.x() >= 0 ? (ix + 1 - gxf) : (gxf - ix)) * cell * inv_x;
    t_max_y = (d.y() >= 0 ? (iy + 1 - gyf) : (gyf - iy)) * cell * inv_y;
    t_delta_x = cell * inv_x;
    t_delta_y = cell * inv_y;
  }
  [[nodiscard]] double exit() const { return std::min(t_max_x, t_max_y); }
  void step() {
    if (t_max_x < t_max_y) {
      ix += step_x;
      t_max_x += t_delta_x;
    } else {
      iy += step_y;
      t_max_y += t_delta_y;
    }
  }

  int ix = 0, iy = 0, step_x = 1, step_y = 1;
  double t_max_x = 0, t_max_y = 0, t_delta_x = 0, t_delta_y = 0;
};

// The return of object `p` hit at `range` (surface normal from `iv`).
RayHit object_hit(const Primitive& p, const Interval& iv, const Eigen::Vector3d& d, double range) {
  RayHit hit;
  hit.hit = true;
  hit.range = range;
  hit.label = p.label;
  hit.instance = p.instance;
  const double cos_inc = std::abs(iv.normal.dot(d));
  hit.remission = static_cast<float>(p.remission * (0.55 + 0.45 * cos_inc));
  return hit;
}
}  // namespace

World::RayOrigin World::ray_origin(const Eigen::Vector3d& position) const {
  return {position, position.z() - ground_height(position.x(), position.y())};
}

RayHit World::cast_ray(const RayOrigin& origin, const Eigen::Vector3d& d, double max_range, double t,
                       std::span<const Primitive> dynamic, Rng& rng) const {
  const Eigen::Vector3d& o = origin.position;
  RayHit best;
  // The nearest surface so far is the ground or the nearest object; the
  // ground is marched only as far as the comparisons below need.
  GroundMarch ground(*this, origin, d, max_range);
  double object_t = max_range + 1e-9;  // nearest object (or glass) so far, capped at the range
  const auto nearer = [&](double x) { return x < object_t && ground.beyond(x); };
  const Primitive* best_p = nullptr;
  Interval best_iv;
  bool blocked = false;  // a glass pane ate the return

  auto consider = [&](const Primitive& p) {
    if (!p.present(t)) return;
    Interval iv;
    if (!intersect(p, o, d, iv) || !nearer(iv.t0)) return;
    const double r = surface_range(p, iv, o, d, rng);
    if (r == -kInf) {  // window glass: nothing behind it comes back either
      object_t = iv.t0;
      best_p = nullptr;
      blocked = true;
      return;
    }
    if (nearer(r)) {
      object_t = r;
      best_p = &p;
      best_iv = iv;
      blocked = false;
    }
  };
  for (const auto& p : dynamic) consider(p);

  // 2D DDA over the object grid, mailboxing repeated primitives.
  GridWalk walk(o, d, ground_.origin, options_.object_cell);
  std::array<std::uint32_t, 48> tested{};
  std::size_t n_tested = 0;
  double t_cell_start = 0.0;
  while (nearer(t_cell_start)) {
    if (walk.ix < 0 || walk.iy < 0 || walk.ix >= gx_ || walk.iy >= gy_) break;
    const std::size_t c =
        static_cast<std::size_t>(walk.iy) * static_cast<std::size_t>(gx_) + static_cast<std::size_t>(walk.ix);
    for (std::uint32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
      const std::uint32_t id = cell_items_[k];
      const auto tested_end = tested.begin() + static_cast<std::ptrdiff_t>(n_tested);
      if (std::find(tested.begin(), tested_end, id) != tested_end) continue;
      if (n_tested < tested.size()) tested[n_tested++] = id;
      consider(primitives_[id]);
    }
    const double t_exit = walk.exit();
    if (!nearer(t_exit)) break;
    t_cell_start = t_exit;
    walk.step();
  }

  // An object was kept only where the ground crosses beyond it; otherwise the
  // ground is the nearest surface (or nothing within range).
  const double best_t = ground.beyond(object_t) ? object_t : ground.crossing();
  if (blocked || best_t > max_range) return best;
  return best_p != nullptr ? object_hit(*best_p, best_iv, d, best_t) : ground_hit(o, d, best_t);
}

RayHit World::ground_hit(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double range) const {
  RayHit hit;
  hit.hit = true;
  hit.range = range;
  const Eigen::Vector3d p = o + range * d;
  const GroundInfo g = ground_at(p.x(), p.y());
  hit.label = g.label;
  hit.remission = static_cast<float>(g.remission * (0.6 + 0.4 * std::min(1.0, std::abs(d.z()) * 4.0)));
  return hit;
}

}  // namespace saloam
