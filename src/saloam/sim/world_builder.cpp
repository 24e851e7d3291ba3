// Procedural construction of the street world along a trajectory: ground
// raster (distance to the path, height, street layout), static objects
// placed greedily with collision checks (so a revisited street is filled
// once, not twice), moving agents, and the ray-casting grid.

#include <algorithm>
#include <limits>
#include <cstdio>
#include <cmath>
#include <unordered_map>

#include "saloam/core/error.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/sim/world.hpp"

namespace saloam {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Open country (no sidewalks, few buildings) where the rural noise exceeds
// this: KITTI's sequences are mostly town and suburb.
constexpr double kRuralNoise = 0.78;

// Streets with cars parked along the curbs (where the parking noise exceeds
// this), the strip they take on each side [m] and the share of its length
// they fill.
constexpr double kCurbParkingNoise = 0.6;
constexpr float kCurbParkingWidth = 2.0f;
constexpr double kCurbParkedShare = 0.75;

// Objects stand at least this far off a road without sidewalk [m].
constexpr double kRoadsideMargin = 0.5;
// Hedges and fences along a street stand this far behind the sidewalk [m],
// and may come this close to it [m] where the sidewalk widens along them
// (other objects keep 0.1 m clear); a fence is checked and marked as this
// half-width [m] around its line.
constexpr double kLineGap = 0.12;
constexpr double kLineClearance = 0.0;
constexpr double kFenceCheckHalfWidth = 0.3;

enum Salt : std::uint64_t {
  kSaltRoad = 101, kSaltParking, kSaltLot, kSaltSidewalk, kSaltVerge, kSaltRural, kSaltBump, kSaltBump2,
  kSaltBuildings, kSaltFences, kSaltTrees, kSaltPoles, kSaltCars, kSaltAgents, kSaltStructures, kSaltVerges
};

}  // namespace

// Access to World's private members for the builder.
class WorldBuilder {
 public:
  WorldBuilder(World& w, std::uint64_t seed) : w_(w), seed_(seed) {}

  /// A step between consecutive trajectory poses longer than this [m] is
  /// the jump between two passes through the world, not a drive.
  static constexpr double kPassJump = 5.0;

  void build_path(const std::vector<Pose>& trajectory) {
    const double h = w_.options_.sensor_height;
    w_.ego_s_.reserve(trajectory.size());
    double s = 0;
    Eigen::Vector3d prev = trajectory.front().translation() - Eigen::Vector3d(0, 0, h);
    w_.path_.push_back(prev);
    w_.path_s_.push_back(0);
    w_.ego_s_.push_back(0);
    for (std::size_t i = 1; i < trajectory.size(); ++i) {
      const Eigen::Vector3d p = trajectory[i].translation() - Eigen::Vector3d(0, 0, h);
      const double len = (p - prev).norm();
      if (len > kPassJump) {
        // The jump from one pass to the next (SimulationOptions::passes):
        // no road along it, no arc length (moving objects do not travel it).
        w_.path_.push_back(p);
        w_.path_s_.push_back(s);
        w_.ego_s_.push_back(s);
        prev = p;
        continue;
      }
      const int pieces = std::max(1, static_cast<int>(std::ceil(len / 0.5)));
      if (len > 1e-6) {
        for (int k = 1; k <= pieces; ++k) {
          const double a = static_cast<double>(k) / pieces;
          w_.path_.push_back(prev + a * (p - prev));
          w_.path_s_.push_back(s + a * len);
        }
      }
      s += len;
      w_.ego_s_.push_back(s);
      prev = p;
    }
  }

  void build_ground() {
    const auto& opt = w_.options_;
    Eigen::Vector2d lo = w_.path_.front().head<2>(), hi = lo;
    for (const auto& p : w_.path_) {
      lo = lo.cwiseMin(p.head<2>());
      hi = hi.cwiseMax(p.head<2>());
    }
    lo.array() -= opt.margin;
    hi.array() += opt.margin;
    w_.origin_ = lo;
    const double cell = opt.ground_cell;
    w_.nx_ = static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)) + 1;
    w_.ny_ = static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)) + 1;
    const std::size_t n = static_cast<std::size_t>(w_.nx_) * static_cast<std::size_t>(w_.ny_);
    if (n > 200'000'000ull) throw ConfigError("trajectory spans too large an area for the simulator's ground raster");

    // Road centre lines: the driven path plus side streets branching off it
    // (dead-end stubs, so that the street has open intersections).
    std::vector<Eigen::Vector3d> centres;
    std::vector<Eigen::Vector2d> centre_dirs;
    for (std::size_t k = 0; k < w_.path_.size(); ++k) {
      const std::size_t k0 = k > 0 ? k - 1 : k, k1 = std::min(w_.path_.size() - 1, k + 1);
      Eigen::Vector2d dir = (w_.path_[k1] - w_.path_[k0]).head<2>();
      centres.push_back(w_.path_[k]);
      centre_dirs.push_back(dir.norm() > 1e-9 ? Eigen::Vector2d(dir.normalized()) : Eigen::Vector2d(1, 0));
    }
    add_side_streets(centres, centre_dirs);

    // Nearest centre-line sample per cell: seed the cells on the lines, then a
    // two-pass propagation (a feature transform, close to the exact Euclidean one).
    std::vector<std::int32_t> source(n, -1);
    w_.distance_.assign(n, std::numeric_limits<float>::infinity());
    auto center = [&](int ix, int iy) {
      return Eigen::Vector2d(lo.x() + (ix + 0.5) * cell, lo.y() + (iy + 0.5) * cell);
    };
    auto idx = [&](int ix, int iy) {
      return static_cast<std::size_t>(iy) * static_cast<std::size_t>(w_.nx_) + static_cast<std::size_t>(ix);
    };
    for (std::size_t k = 0; k < centres.size(); ++k) {
      const int ix = static_cast<int>((centres[k].x() - lo.x()) / cell);
      const int iy = static_cast<int>((centres[k].y() - lo.y()) / cell);
      if (ix < 0 || iy < 0 || ix >= w_.nx_ || iy >= w_.ny_) continue;
      const double dist = (center(ix, iy) - centres[k].head<2>()).norm();
      const std::size_t i = idx(ix, iy);
      if (dist < w_.distance_[i]) {
        w_.distance_[i] = static_cast<float>(dist);
        source[i] = static_cast<std::int32_t>(k);
      }
    }
    auto relax = [&](int ix, int iy, int jx, int jy) {
      if (jx < 0 || jy < 0 || jx >= w_.nx_ || jy >= w_.ny_) return;
      const std::int32_t src = source[idx(jx, jy)];
      if (src < 0) return;
      const double dist = (center(ix, iy) - centres[static_cast<std::size_t>(src)].head<2>()).norm();
      const std::size_t i = idx(ix, iy);
      if (dist < w_.distance_[i]) {
        w_.distance_[i] = static_cast<float>(dist);
        source[i] = src;
      }
    };
    for (int pass = 0; pass < 2; ++pass) {
      for (int iy = 0; iy < w_.ny_; ++iy) {
        for (int ix = 0; ix < w_.nx_; ++ix) {
          relax(ix, iy, ix - 1, iy);
          relax(ix, iy, ix - 1, iy - 1);
          relax(ix, iy, ix, iy - 1);
          relax(ix, iy, ix + 1, iy - 1);
        }
        for (int ix = w_.nx_ - 1; ix >= 0; --ix) relax(ix, iy, ix + 1, iy);
      }
      for (int iy = w_.ny_ - 1; iy >= 0; --iy) {
        for (int ix = w_.nx_ - 1; ix >= 0; --ix) {
          relax(ix, iy, ix + 1, iy);
          relax(ix, iy, ix + 1, iy + 1);
          relax(ix, iy, ix, iy + 1);
          relax(ix, iy, ix - 1, iy + 1);
        }
        for (int ix = 0; ix < w_.nx_; ++ix) relax(ix, iy, ix - 1, iy);
      }
    }

    // Signed lateral offset: which side of the nearest path point's direction.
    w_.lateral_.resize(n);
    for (int iy = 0; iy < w_.ny_; ++iy) {
      for (int ix = 0; ix < w_.nx_; ++ix) {
        const std::size_t i = idx(ix, iy);
        const auto k = static_cast<std::size_t>(source[i]);
        const Eigen::Vector2d& dir = centre_dirs[k];
        const Eigen::Vector2d rel = center(ix, iy) - centres[k].head<2>();
        const double cross = dir.x() * rel.y() - dir.y() * rel.x();
        w_.lateral_[i] = cross >= 0 ? w_.distance_[i] : -w_.distance_[i];
      }
    }

    // Height of the nearest path point, smoothed so that two passes at
    // slightly different heights meet without a step. Ground-truth
    // trajectories are not always consistent in height (KITTI 08 climbs 9 m
    // in its first 13 m with a level car, and passes its start again 6 m
    // higher): no single ground lies 1.73 m under every pose there, so the
    // sensor keeps a physical clearance above this ground (World::sensor_origin).
    w_.height_.resize(n);
    for (std::size_t i = 0; i < n; ++i) w_.height_[i] = static_cast<float>(centres[static_cast<std::size_t>(source[i])].z());
    box_blur(w_.height_, 4);
    box_blur(w_.height_, 4);

    w_.zones_.resize(n);
    w_.bump_.resize(n);
    for (int iy = 0; iy < w_.ny_; ++iy) {
      for (int ix = 0; ix < w_.nx_; ++ix) {
        const Eigen::Vector2d c = center(ix, iy);
        World::Zone z;
        const bool rural = noise_at(hash_combine(seed_, kSaltRural), c.x(), c.y(), 260.0) > kRuralNoise;
        // Right-hand traffic: the path runs in the right lane; the oncoming
        // lane (2.8 m further left) and, on avenues, one more lane lie left.
        // KITTI's towns are mostly narrow two-lane streets: avenues are rare.
        z.road_right = static_cast<float>(1.5 + 0.4 * noise_at(hash_combine(seed_, kSaltRoad), c.x(), c.y(), 140.0));
        const bool avenue = noise_at(hash_combine(seed_, kSaltRoad + 1000), c.x(), c.y(), 300.0) > 0.9;
        z.road_left = z.road_right + 2.8f + (avenue ? 3.3f : 0.0f);
        const double park = noise_at(hash_combine(seed_, kSaltParking), c.x(), c.y(), 55.0);
        const double lot = noise_at(hash_combine(seed_, kSaltLot), c.x(), c.y(), 70.0);
        z.parking = 0.0f;
        // Parking lanes and lots are rare in SemanticKITTI (1.5 % of all
        // points, against 4 % for cars: most of its parked cars stand in
        // driveways, yards and on the road's edge).
        if (!rural && park > 0.75) z.parking = 2.3f;
        if (!rural && lot > 0.985) z.parking = 12.0f;
        // Elsewhere in town most streets have cars parked on the road along
        // both curbs (no marked lane: SemanticKITTI labels the ground road).
        if (!rural && z.parking == 0 && park > kCurbParkingNoise) {
          z.curb_parking = kCurbParkingWidth;
          z.road_right += z.curb_parking;
          z.road_left += z.curb_parking;
        }
        z.sidewalk = rural ? 0.0f
                           : static_cast<float>(1.4 + 1.2 * noise_at(hash_combine(seed_, kSaltSidewalk), c.x(), c.y(), 90.0));
        const double verge = noise_at(hash_combine(seed_, kSaltVerge), c.x(), c.y(), 45.0);
        z.verge = rural || verge < 0.72 ? 0 : (verge < 0.86 ? 1 : 2);
        const std::size_t i = idx(ix, iy);
        w_.zones_[i] = z;
        w_.bump_[i] = static_cast<float>(0.7 * noise_at(hash_combine(seed_, kSaltBump), c.x(), c.y(), 14.0) +
                                         0.8 * noise_at(hash_combine(seed_, kSaltBump2), c.x(), c.y(), 55.0) - 0.6);
      }
    }
    w_.packed_.resize(n);
    for (std::size_t i = 0; i < n; ++i) w_.packed_[i] = {w_.distance_[i], w_.height_[i], w_.bump_[i], 0.0f};
    bound_ground_rise();
    occupied_.assign(n, 0);
  }

  // Bounds on how fast the ground surface rises along any horizontal
  // direction [m per m], tile by tile, away from curbs and zone edges
  // (World::kGroundStep): the height and the bump are bilinear between raster
  // nodes, so each changes along a direction at most by its largest x step
  // plus its largest y step per cell; the verge fades the bump in over 12 m.
  // And on how high the ground gets in each tile: a bilinear value is at most
  // its largest node. A tile's bounds cover the raster patches that reach
  // into it.
  void bound_ground_rise() {
    const int tile = World::kRiseTile;
    w_.rise_nx_ = (w_.nx_ + tile - 1) / tile;
    w_.rise_ny_ = (w_.ny_ + tile - 1) / tile;
    const std::size_t tiles = static_cast<std::size_t>(w_.rise_nx_) * static_cast<std::size_t>(w_.rise_ny_);
    w_.ground_rise_.assign(tiles, 0.0f);
    // Highest raster height and bump reaching into each tile: the ground
    // (World::ground_from) is at most their sum plus the curb.
    std::vector<float> top_height(tiles, -std::numeric_limits<float>::infinity()), top_bump(tiles, 0.0f);
    auto idx = [&](int ix, int iy) {
      return static_cast<std::size_t>(iy) * static_cast<std::size_t>(w_.nx_) + static_cast<std::size_t>(ix);
    };
    for (int iy = 0; iy < w_.ny_; ++iy) {
      for (int ix = 0; ix < w_.nx_; ++ix) {
        const std::size_t i = idx(ix, iy);
        float step_height = 0.0f, step_bump = 0.0f;
        for (const std::size_t j : {ix + 1 < w_.nx_ ? idx(ix + 1, iy) : i, iy + 1 < w_.ny_ ? idx(ix, iy + 1) : i}) {
          step_height = std::max(step_height, std::abs(w_.height_[j] - w_.height_[i]));
          step_bump = std::max(step_bump, std::abs(w_.bump_[j] - w_.bump_[i]));
        }
        const float rise = static_cast<float>(2.0 * (step_height + step_bump) / w_.options_.ground_cell +
                                              std::abs(w_.bump_[i]) / 12.0 + 1e-3);
        // The node's patches span [ix - 1, ix + 1]: every tile they reach.
        for (int ty = std::max(0, iy - 1) / tile; ty <= std::min(w_.ny_ - 1, iy + 1) / tile; ++ty) {
          for (int tx = std::max(0, ix - 1) / tile; tx <= std::min(w_.nx_ - 1, ix + 1) / tile; ++tx) {
            const std::size_t t = static_cast<std::size_t>(ty) * static_cast<std::size_t>(w_.rise_nx_) + static_cast<std::size_t>(tx);
            w_.ground_rise_[t] = std::max(w_.ground_rise_[t], rise);
            top_height[t] = std::max(top_height[t], w_.height_[i]);
            top_bump[t] = std::max(top_bump[t], w_.bump_[i]);
          }
        }
      }
    }
    w_.ground_top_.resize(tiles);
    for (std::size_t t = 0; t < tiles; ++t) {
      w_.ground_top_[t] = static_cast<float>(top_height[t] + std::max(World::kCurbHeight, World::kParkingRise) + top_bump[t] + 1e-3);
    }
  }

  void add_side_streets(std::vector<Eigen::Vector3d>& centres, std::vector<Eigen::Vector2d>& dirs) {
    Rng rng(hash_combine(seed_, kSaltRoad + 7));
    PointSet junctions;
    const double len = w_.path_length();
    for (double s = rng.uniform(20, 80); s < len - 10; s += rng.uniform(100, 250)) {
      Eigen::Vector3d pos;
      Eigen::Vector2d dir;
      w_.path_point(s, pos, dir);
      // Not on open land, and one junction per place even where the path passes twice.
      if (noise_at(hash_combine(seed_, kSaltRural), pos.x(), pos.y(), 260.0) > kRuralNoise) continue;
      if (!far_from(junctions, pos.head<2>(), 50.0)) continue;
      // Only on straight stretches: a side street off a bend would run askew.
      Eigen::Vector3d before, after;
      Eigen::Vector2d dir_before, dir_after;
      w_.path_point(s - 15.0, before, dir_before);
      w_.path_point(s + 15.0, after, dir_after);
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
  void box_blur(std::vector<float>& f, int radius) const {
    const int nx = w_.nx_, ny = w_.ny_;
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

  // ------------------------------------------------------------ placement helpers

  /// How far behind the street's edge (street_edge) a hedge, fence or bed
  /// along it starts at the nearest: just behind the sidewalk, or beyond a
  /// country road's margin (rect_free).
  static double line_gap(bool rural) { return rural ? kRoadsideMargin + 0.02 : kLineGap; }

  /// Lateral distance from the path to the back of the sidewalk on one side.
  [[nodiscard]] double street_edge(const Eigen::Vector2d& p, int side) const {
    const World::Zone z = w_.zone_at(p.x(), p.y());
    return z.road(side) + z.parking + z.sidewalk;
  }
  [[nodiscard]] bool inside_grid(const Eigen::Vector2d& p) const {
    return p.x() > w_.origin_.x() + 1 && p.y() > w_.origin_.y() + 1 &&
           p.x() < w_.origin_.x() + (w_.nx_ - 1) * w_.options_.ground_cell &&
           p.y() < w_.origin_.y() + (w_.ny_ - 1) * w_.options_.ground_cell;
  }

  // Samples of an oriented rectangle (centre, axis, half extents), 0.5 m apart.
  template <class F>
  bool for_rect(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy, F&& f) const {
    const Eigen::Vector2d side(-axis.y(), axis.x());
    const int nx = std::max(1, static_cast<int>(std::ceil(2 * hx / 0.5))), ny = std::max(1, static_cast<int>(std::ceil(2 * hy / 0.5)));
    for (int i = 0; i <= nx; ++i) {
      for (int j = 0; j <= ny; ++j) {
        const Eigen::Vector2d p = c + (-hx + 2 * hx * i / nx) * axis + (-hy + 2 * hy * j / ny) * side;
        if (!f(p)) return false;
      }
    }
    return true;
  }

  /// Rectangle clear of the street (up to `street_clearance` beyond the
  /// street edge, or beyond the road when `road_only`) and of other objects.
  bool rect_free(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy, double clearance,
                 bool road_only) const {
    return for_rect(c, axis, hx, hy, [&](const Eigen::Vector2d& p) {
      if (!inside_grid(p)) return false;
      const World::Zone z = w_.zone_at(p.x(), p.y());
      // Off the street: a margin from the road even where there is no sidewalk.
      const double limit = road_only ? clearance : std::max(z.parking + z.sidewalk + clearance, kRoadsideMargin);
      return w_.road_margin(p.x(), p.y()) >= limit && occupied_[w_.cell_index(p.x(), p.y())] == 0;
    });
  }
  void mark_rect(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy) {
    if (run_marks_) {
      run_marks_->push_back({c, axis, hx, hy});
      return;
    }
    for_rect(c, axis, hx, hy, [&](const Eigen::Vector2d& p) {
      if (inside_grid(p)) occupied_[w_.cell_index(p.x(), p.y())] = 1;
      return true;
    });
  }

  /// Places the pieces of one run (hedge, fence) with `place`, marking their
  /// ground only once all are placed: the pieces of a run meet end to end,
  /// and each would otherwise find its neighbour's marked cells (the raster
  /// is coarser than the gap between them) and leave the run in dashes.
  template <class F>
  void as_one_run(F&& place) {
    std::vector<MarkedRect> marks;
    run_marks_ = &marks;
    place();
    run_marks_ = nullptr;
    for (const MarkedRect& m : marks) mark_rect(m.c, m.axis, m.hx, m.hy);
  }
  /// Square of half side r clear of the road by `clearance` (objects ignored).
  bool clear_of_road(const Eigen::Vector2d& c, double r, double clearance) const {
    return for_rect(c, {1, 0}, r, r, [&](const Eigen::Vector2d& p) {
      return inside_grid(p) && w_.road_margin(p.x(), p.y()) >= clearance;
    });
  }
  bool disc_free(const Eigen::Vector2d& c, double r, double road_clearance) const {
    return rect_free(c, {1, 0}, r, r, road_clearance, true);
  }

  Primitive box(std::uint16_t label, const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy,
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
  static Primitive cylinder(std::uint16_t label, const Eigen::Vector2d& c, double radius, double z0, double z1,
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
  [[nodiscard]] double ground(const Eigen::Vector2d& p) const { return w_.ground_height(p.x(), p.y()); }

  // Walks the path in steps, calling f(position, direction, s).
  template <class F>
  void walk(double start, F&& f) const {
    double s = start;
    const double len = w_.path_length();
    while (s < len) {
      Eigen::Vector3d pos;
      Eigen::Vector2d dir;
      w_.path_point(s, pos, dir);
      const double advance = f(pos.head<2>(), dir, s);
      s += std::max(0.5, advance);
    }
  }

  // ------------------------------------------------------------ objects

  void place_buildings(double total_time) {
    for (int side = -1; side <= 1; side += 2) {
      Rng rng(hash3(seed_, kSaltBuildings, static_cast<std::uint64_t>(side + 5)));
      walk(rng.uniform(0, 10), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
        const Eigen::Vector2d left(-dir.y(), dir.x());
        const Eigen::Vector2d probe = p + side * left * 8.0;
        const World::Zone z = w_.zone_at(probe.x(), probe.y());
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
          // A car in the driveway of some front gardens (most of KITTI's parked
          // cars are off the parking lanes, which hold 1.5 % of its points).
          if (setback > 5.5 && rng.chance(0.7)) {
            const Eigen::Vector2d d = p + rng.uniform(0.15, 0.85) * length * axis + side * mleft * (edge + 1.7 + 2.5);
            const double car_length = rng.uniform(3.9, 4.9);
            if (rect_free(d, mleft, 0.5 * car_length + 0.15, 1.05, 0.5, false)) {
              add_vehicle(d, mleft * (rng.chance(0.5) ? 1.0 : -1.0), cls::kCar, car_length, rng.uniform(1.7, 1.9),
                          rng.uniform(1.4, 1.65), rng, total_time);
              mark_rect(d, mleft, 0.5 * car_length + 0.15, 1.05);
            }
          }
          // Shrubs along the house front (foundation planting) on some plots.
          if (setback > 2.5 && rng.chance(0.5)) {
            const Eigen::Vector2d front = p + 0.5 * length * axis + side * mleft * (edge + setback - 0.6);
            add_hedge(front, axis, 0.5 * length - 0.5, 0.45, rng.uniform(0.7, 1.6), rng);
          }
          const double gap = rng.chance(0.4) ? rng.uniform(0.0, 1.0) : rng.uniform(2, 14);
          // Trees and shrubs fill most gaps between houses.
          if (gap > 2.5 && rng.chance(0.8)) {
            const double r = std::min(0.5 * gap - 0.4, rng.uniform(1.5, 3.5));
            const Eigen::Vector2d g = p + (length + 0.5 * gap) * axis + side * mleft * (edge + setback + rng.uniform(1.0, 0.5 * depth + 2.0));
            if (r > 0.8 && rect_free(g, {1, 0}, r, r, 1.0, false)) {
              if (rng.chance(0.6)) add_tree(g, r + 0.8, rng); else add_bush(g, r, rng);
              mark_rect(g, {1, 0}, r, r);
            }
          }
          return length + gap;
        }
        return 4.0;
      });
    }
  }

  void add_building(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy, double height, Rng& rng) {
    const double g = lowest_ground(c, axis, hx, hy);
    Primitive b = box(cls::kBuilding, c, axis, hx, hy, g - 0.5, g + height, rng.uniform(0.12, 0.42));
    b.facade.floor_height = static_cast<float>(rng.uniform(2.8, 3.6));
    b.facade.window_spacing = static_cast<float>(rng.uniform(2.4, 3.8));
    b.facade.window_width = static_cast<float>(std::min(b.facade.window_spacing - 0.6, rng.uniform(0.9, 1.8)));
    b.facade.window_height = static_cast<float>(rng.uniform(1.1, 1.8));
    b.facade.recess = static_cast<float>(rng.uniform(0.12, 0.35));
    b.facade.glass_dropout = static_cast<float>(rng.uniform(0.25, 0.7));
    if (rng.chance(0.15)) b.facade.floor_height = 0;  // plain wall (warehouse, garage)
    w_.primitives_.push_back(b);
    // A plinth that sticks out a little: facades are not perfect planes.
    if (rng.chance(0.5)) {
      w_.primitives_.push_back(box(cls::kBuilding, c, axis, hx + 0.12, hy + 0.12, g - 0.5, g + rng.uniform(0.4, 1.0),
                                   b.remission * 0.8));
    }
    // Pilasters or balconies every few metres on some buildings.
    if (rng.chance(0.35) && height > 7) {
      const Eigen::Vector2d side(-axis.y(), axis.x());
      const double spacing = rng.uniform(4, 8);
      for (double u = -hx + 1; u < hx - 1; u += spacing) {
        for (int s = -1; s <= 1; s += 2) {
          const Eigen::Vector2d pc = c + u * axis + s * (hy + 0.2) * side;
          w_.primitives_.push_back(box(cls::kBuilding, pc, axis, 0.25, 0.2, g, g + height, b.remission));
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
      w_.primitives_.push_back(top);
    }
  }

  double lowest_ground(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy) const {
    double g = std::numeric_limits<double>::infinity();
    for_rect(c, axis, hx, hy, [&](const Eigen::Vector2d& p) {
      g = std::min(g, ground(p));
      return true;
    });
    return g;
  }

  /// Along a property line that starts at `front` (the back of the
  /// sidewalk; `away` points from the street into the plot): a hedge, or a
  /// fence with shrubs or a hedge behind it, each as close to the sidewalk
  /// as the clearance check allows (kLineGap).
  void property_line(const Eigen::Vector2d& front, const Eigen::Vector2d& axis, const Eigen::Vector2d& away,
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

  /// Places a straight run in pieces of at most ~5 m, each checked on its
  /// own, so that a run along a curving street or a skewed plot keeps the
  /// pieces that fit instead of failing as a whole. Returns the pieces placed.
  template <class F>
  int in_pieces(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, F&& place_piece) {
    const int pieces = std::max(1, static_cast<int>(std::ceil(2.0 * half_length / 5.0)));
    const double half_piece = half_length / pieces;
    int placed = 0;
    as_one_run([&] {
      for (int k = 0; k < pieces; ++k) {
        const Eigen::Vector2d pc = c + (-half_length + (2 * k + 1) * half_piece) * axis;
        placed += place_piece(pc, half_piece) ? 1 : 0;
      }
    });
    return placed;
  }

  bool add_hedge(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, double half_width,
                 double height, Rng& rng) {
    return in_pieces(c, axis, half_length, [&](const Eigen::Vector2d& pc, double half) {
             return add_hedge_piece(pc, axis, half, half_width, height, rng);
           }) > 0;
  }

  bool add_hedge_piece(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, double half_width,
                       double height, Rng& rng) {
    if (!rect_free(c, axis, half_length, half_width, kLineClearance, false)) return false;
    const double g = ground(c);
    Primitive h = box(cls::kVegetation, c, axis, half_length, half_width, g - 0.1, g + height, rng.uniform(0.38, 0.5));
    h.mean_free_path = 0.3f;
    w_.primitives_.push_back(h);
    mark_rect(c, axis, half_length, half_width);
    return true;
  }

  /// What a fence is made of: boards or railings, or chain-link the beam partly passes.
  struct FenceStyle {
    bool chain_link = false;
    double height = 1.5, remission = 0.3;
  };
  static FenceStyle fence_style(double height, double chain_link, Rng& rng) {
    FenceStyle f;
    f.chain_link = rng.chance(chain_link);
    f.height = height;
    f.remission = rng.uniform(0.2, 0.5);
    return f;
  }

  bool add_fence(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, double height,
                 double chain_link, Rng& rng) {
    const FenceStyle style = fence_style(height, chain_link, rng);
    return in_pieces(c, axis, half_length, [&](const Eigen::Vector2d& pc, double half) {
             return add_fence_piece(pc, axis, half, style);
           }) > 0;
  }

  bool add_fence_piece(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, const FenceStyle& style) {
    if (!rect_free(c, axis, half_length, kFenceCheckHalfWidth, kLineClearance, false)) return false;
    const double g = ground(c);
    Primitive f = box(cls::kFence, c, axis, half_length, 0.04, g, g + style.height, style.remission);
    if (style.chain_link) {
      f.half_y = 0.2f;
      f.mean_free_path = 1.0f;
    }
    w_.primitives_.push_back(f);
    mark_rect(c, axis, half_length, kFenceCheckHalfWidth);
    return true;
  }

  /// Shrubs or a hedge just behind a fence, taller than it now and then.
  void planting_behind(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, const Eigen::Vector2d& away,
                       double half_length, Rng& rng) {
    if (rng.chance(0.45)) {
      const double hw = rng.uniform(0.4, 0.9);
      add_hedge(c + away * (0.45 + hw), axis, half_length, hw, rng.uniform(1.2, 2.8), rng);
      return;
    }
    for (double u = -half_length + 0.8; u < half_length - 0.5; u += rng.uniform(1.5, 3.5)) {
      const double r = rng.uniform(0.6, 1.6);
      const Eigen::Vector2d b = c + u * axis + away * (0.4 + r);
      if (!rect_free(b, {1, 0}, r, r, 0.1, false)) continue;
      add_bush(b, r, rng);
      mark_rect(b, {1, 0}, r, r);
    }
  }

  /// One piece of a run along the street: centre, direction along the
  /// street, direction away from it, half its length.
  struct RunPiece {
    Eigen::Vector2d c, axis, away;
    double half_length;
  };

  /// A run of `length` [m] from arc length s along one side of the street,
  /// `offset` [m] behind the back of the sidewalk, in pieces of at most 5 m
  /// that each follow the path (bends, the sidewalk's changing width); place
  /// returns whether a piece went in (as_one_run). Returns the pieces placed.
  template <class F>
  std::vector<RunPiece> along_street(double s, int side, double length, double offset, F&& place) {
    const int pieces = std::max(1, static_cast<int>(std::ceil(length / 5.0)));
    const double half = 0.5 * length / pieces;
    std::vector<RunPiece> placed;
    as_one_run([&] {
      for (int k = 0; k < pieces; ++k) {
        Eigen::Vector3d pos;
        Eigen::Vector2d dir;
        w_.path_point(s + (2 * k + 1) * half, pos, dir);
        const Eigen::Vector2d away = side * Eigen::Vector2d(-dir.y(), dir.x());
        const double edge = street_edge(pos.head<2>() + away * 7.0, side);
        const RunPiece piece{pos.head<2>() + away * (edge + offset), dir, away, half};
        if (place(piece)) placed.push_back(piece);
      }
    });
    return placed;
  }

  // Hedges and fences along the back of the sidewalk wherever no building
  // stands there: streets in KITTI are lined with them.
  void place_boundaries() {
    for (int side = -1; side <= 1; side += 2) {
      Rng rng(hash3(seed_, kSaltFences, static_cast<std::uint64_t>(side + 5)));
      walk(rng.uniform(0, 10), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double s) -> double {
        const Eigen::Vector2d left(-dir.y(), dir.x());
        const Eigen::Vector2d probe = p + side * left * 7.0;
        const bool rural = w_.zone_at(probe.x(), probe.y()).sidewalk == 0;
        const double length = rng.uniform(6, 30);
        const double pick = rng.uniform();
        if (pick < (rural ? 0.03 : 0.04)) return length;  // open
        // Country roads: wide belts of shrubs along the field edges.
        const double half_w = rural ? rng.uniform(0.6, 1.8) : rng.uniform(0.35, 0.8);
        // Street side of the hedge or fence just behind the sidewalk, or
        // behind a country road's shoulder (rect_free keeps objects
        // kRoadsideMargin off a road without sidewalk).
        const double gap = line_gap(rural) + rng.uniform(0.0, rural ? 0.4 : 0.15);
        const bool hedge = pick < (rural ? 0.85 : 0.5);
        const double hedge_height = rng.uniform(1.4, rural ? 4.0 : 2.8);
        const FenceStyle fence = fence_style(rng.uniform(1.0, 2.2), 0.3, rng);
        const bool planted = !hedge && rng.chance(rural ? 0.6 : 0.85);
        const double depth = hedge ? half_w : kFenceCheckHalfWidth;
        const std::vector<RunPiece> placed = along_street(s, side, length, gap + depth, [&](const RunPiece& piece) {
          return hedge ? add_hedge_piece(piece.c, piece.axis, piece.half_length, half_w, hedge_height, rng)
                       : add_fence_piece(piece.c, piece.axis, piece.half_length, fence);
        });
        if (placed.empty()) return 2.0;
        if (planted) {
          for (const RunPiece& piece : placed) planting_behind(piece.c, piece.axis, piece.away, piece.half_length, rng);
        }
        return length + (rng.chance(0.75) ? 0.0 : rng.uniform(1, 4));
      });
    }
  }

  // Shrub beds and low hedges on whatever verge is still bare behind the
  // sidewalk (or the rural road's edge) once plots, fences and trees are
  // placed: KITTI's streets are lined with planting, and SemanticKITTI has
  // 3.4 times as many vegetation points as terrain points (26.7 % vs 7.8 %).
  // Driveways and paths leave about one bed in six out.
  void plant_verges() {
    for (int side = -1; side <= 1; side += 2) {
      Rng rng(hash3(seed_, kSaltVerges, static_cast<std::uint64_t>(side + 5)));
      walk(rng.uniform(0, 3), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
        const Eigen::Vector2d left(-dir.y(), dir.x());
        const double half_length = rng.uniform(0.8, 1.6);
        if (rng.chance(0.1)) return 2 * half_length + rng.uniform(1.0, 4.0);
        const double half_w = rng.uniform(0.4, 1.2);
        const Eigen::Vector2d probe = p + side * left * 7.0;
        const double edge = street_edge(probe, side);
        const bool rural = w_.zone_at(probe.x(), probe.y()).sidewalk == 0;
        const double gap = line_gap(rural);
        const Eigen::Vector2d c = p + half_length * dir + side * left * (edge + gap + half_w);
        if (!rect_free(c, dir, half_length, half_w, kLineClearance, false)) return 0.5;
        const double g = ground(c);
        const double height = 0.5 + 1.3 * noise_at(hash_combine(seed_, kSaltVerges), c.x(), c.y(), 12.0) + rng.uniform(0.0, 0.3);
        Primitive bed = box(cls::kVegetation, c, dir, half_length, half_w, g - 0.1, g + height, rng.uniform(0.35, 0.5));
        bed.mean_free_path = static_cast<float>(rng.uniform(0.25, 0.5));
        w_.primitives_.push_back(bed);
        mark_rect(c, dir, half_length, half_w);
        return 2 * half_length;
      });
    }
  }

  void place_street_furniture() {
    // Street lights and signs near the curb, trees in the verge.
    for (int side = -1; side <= 1; side += 2) {
      Rng rng(hash3(seed_, kSaltPoles, static_cast<std::uint64_t>(side + 5)));
      walk(rng.uniform(0, 20), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
        const Eigen::Vector2d left(-dir.y(), dir.x());
        const World::Zone z = w_.zone_at(p.x() + side * left.x() * 6, p.y() + side * left.y() * 6);
        const double off = z.road(side) + z.parking + (z.sidewalk > 0 ? 0.45 : 1.2);
        const Eigen::Vector2d c = p + side * left * off;
        if (!far_from(poles_, c, 9.0) || !disc_free(c, 0.3, 0.25)) return 3.0;
        const double g = ground(c);
        if (rng.chance(0.7)) {  // street light with an arm over the road
          // Draws kept in sequence (radius, height, remission): the world must not change.
          const double radius = rng.uniform(0.09, 0.14);
          const double h = rng.uniform(6, 9);
          const Primitive pole = cylinder(cls::kPole, c, radius, g, g + h, rng.uniform(0.25, 0.45));
          w_.primitives_.push_back(pole);
          const Eigen::Vector2d arm_c = c - side * left * 0.9;
          w_.primitives_.push_back(box(cls::kPole, arm_c, left, 0.9, 0.07, g + h - 0.15, g + h, pole.remission));
        } else {  // traffic sign on a thin post, the plate facing traffic
          const double radius = rng.uniform(0.04, 0.06);
          const double h = rng.uniform(2.0, 2.8);
          w_.primitives_.push_back(cylinder(cls::kPole, c, radius, g, g + h, 0.35));
          const double plate = rng.uniform(0.3, 0.45);
          Primitive sign = box(cls::kTrafficSign, c, dir, 0.025, plate, g + h, g + h + 2 * plate, rng.uniform(0.75, 0.95));
          w_.primitives_.push_back(sign);
        }
        poles_.push_back(c);
        mark_rect(c, dir, 0.3, 0.3);
        return rng.uniform(10, 26);
      });
    }
  }

  // Trees after hedges and fences: crowns may overhang them (and gardens),
  // only the trunk needs free ground; no crown reaches over the road.
  void place_trees() {
    for (int side = -1; side <= 1; side += 2) {
      Rng rng(hash3(seed_, kSaltTrees, static_cast<std::uint64_t>(side + 5)));
      walk(rng.uniform(0, 10), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
        const Eigen::Vector2d left(-dir.y(), dir.x());
        const Eigen::Vector2d probe = p + side * left * 7.0;
        const World::Zone z = w_.zone_at(probe.x(), probe.y());
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
    // Scattered trees and bushes further from the street (parks, fields, yards).
    Rng rng(hash_combine(seed_, kSaltTrees + 50));
    walk(0.0, [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
      const Eigen::Vector2d left(-dir.y(), dir.x());
      const bool rural_here = w_.zone_at(p.x(), p.y()).sidewalk == 0;
      for (int k = 0; k < (rural_here ? 90 : 70); ++k) {
        const int side = rng.chance(0.5) ? -1 : 1;
        const Eigen::Vector2d c = p + side * left * rng.uniform(5, 60) + dir * rng.uniform(-5, 5);
        if (!inside_grid(c)) continue;
        const World::Zone zc = w_.zone_at(c.x(), c.y());
        if (w_.road_margin(c.x(), c.y()) < zc.parking + zc.sidewalk + 2) continue;
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

  void add_tree(const Eigen::Vector2d& c, double crown, Rng& rng) {
    const double g = ground(c);
    // Crowns from 1.2-2.4 m up, as on KITTI's street and garden trees (maples,
    // limes, fruit trees): the near-horizontal beams meet the foliage.
    const double trunk_h = rng.uniform(1.2, 2.4);
    const double radius = rng.uniform(0.1, 0.25);
    w_.primitives_.push_back(cylinder(cls::kTrunk, c, radius, g, g + trunk_h + crown * 0.8, rng.uniform(0.25, 0.4)));
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
    w_.primitives_.push_back(leaves);
  }

  /// A low, wide mound of shrubs on open ground (a flattened ellipsoid).
  void add_shrub_patch(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double rx, double ry, double height, Rng& rng) {
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
    w_.primitives_.push_back(b);
  }

  void add_bush(const Eigen::Vector2d& c, double r, Rng& rng) {
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
    w_.primitives_.push_back(b);
  }

  void place_structures() {
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
        w_.primitives_.push_back(shelter);
        w_.primitives_.push_back(box(cls::kOtherStructure, c + side * left * 0.75, dir, 1.8, 0.05, g, g + 2.1, 0.5));
        mark_rect(c, dir, 2.0, 1.0);
      } else {  // low wall
        const double half = rng.uniform(3, 10);
        if (!rect_free(c, dir, half, 0.3, 0.1, false)) return 10.0;
        w_.primitives_.push_back(box(cls::kOtherStructure, c, dir, half, 0.15, g - 0.1, g + rng.uniform(0.5, 1.2), 0.35));
        mark_rect(c, dir, half, 0.3);
      }
      return rng.uniform(120, 300);
    });
  }

  void place_parked_vehicles(double total_time) {
    for (int side = -1; side <= 1; side += 2) {
      Rng rng(hash3(seed_, kSaltCars, static_cast<std::uint64_t>(side + 5)));
      walk(rng.uniform(0, 5), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double) -> double {
        const Eigen::Vector2d left(-dir.y(), dir.x());
        const World::Zone z = w_.zone_at(p.x() + side * left.x() * 6, p.y() + side * left.y() * 6);
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

  void add_vehicle(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, std::uint16_t label, double length,
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
    w_.primitives_.push_back(body);
    w_.primitives_.push_back(cabin);
  }

  void place_agents(double total_time) {
    if (!w_.options_.dynamic_objects) return;
    Rng rng(hash_combine(seed_, kSaltAgents));
    std::uint16_t inst = 1000;
    // Oncoming cars in the left lane, each meeting the ego at some time.
    for (double t = rng.uniform(1, 5); t < total_time; t += rng.uniform(4, 11)) {
      Agent a;
      a.label = cls::kMovingCar;
      a.instance = inst++;
      a.t_ref = t;
      a.s_ref = w_.ego_arc_length(t);
      a.speed = -rng.uniform(7, 13);
      a.lateral = rng.uniform(2.9, 3.2);  // the oncoming lane, clear of cars parked at its curb
      a.t_begin = t - 15;
      a.t_end = t + 15;
      vehicle_dims(a, rng);
      w_.agents_.push_back(a);
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
      w_.agents_.push_back(a);
    }
    // Pedestrians on the sidewalks, walking either way.
    for (double t = rng.uniform(0, 4); t < total_time; t += rng.uniform(2, 7)) {
      Agent a;
      a.label = cls::kMovingPerson;
      a.instance = inst++;
      a.t_ref = t;
      a.s_ref = w_.ego_arc_length(t) + rng.uniform(-10, 30);
      a.speed = (rng.chance(0.5) ? 1 : -1) * rng.uniform(1.0, 1.6);
      a.sidewalk_side = rng.chance(0.5) ? 1 : -1;
      a.t_begin = t - 25;
      a.t_end = t + 25;
      a.width = static_cast<float>(rng.uniform(0.38, 0.5));
      a.height = static_cast<float>(rng.uniform(1.6, 1.9));
      a.remission = static_cast<float>(rng.uniform(0.15, 0.4));
      a.gap_phase = rng.uniform(0, 2 * kPi);
      w_.agents_.push_back(a);
    }
  }

  static void vehicle_dims(Agent& a, Rng& rng) {
    a.length = static_cast<float>(rng.uniform(4.0, 4.9));
    a.width = static_cast<float>(rng.uniform(1.72, 1.9));
    a.height = static_cast<float>(rng.uniform(1.4, 1.65));
    a.remission = static_cast<float>(rng.uniform(0.08, 0.6));
  }

  void build_grid() {
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

 private:
  // Points on a coarse hash grid, to keep a minimum spacing between objects
  // of one kind (a street driven twice gets one row of poles, not two).
  struct PointSet {
    static constexpr double kCell = 20.0;
    std::unordered_map<std::uint64_t, std::vector<Eigen::Vector2d>> cells;
    static std::uint64_t key(std::int64_t ix, std::int64_t iy) {
      return (static_cast<std::uint64_t>(ix) << 32) ^ (static_cast<std::uint64_t>(iy) & 0xffffffffull);
    }
    void push_back(const Eigen::Vector2d& p) {
      cells[key(static_cast<std::int64_t>(std::floor(p.x() / kCell)), static_cast<std::int64_t>(std::floor(p.y() / kCell)))]
          .push_back(p);
    }
  };
  static bool far_from(const PointSet& set, const Eigen::Vector2d& c, double min_dist) {
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

  World& w_;
  std::uint64_t seed_;
  std::vector<std::uint8_t> occupied_;
  struct MarkedRect {
    Eigen::Vector2d c, axis;
    double hx, hy;
  };
  std::vector<MarkedRect>* run_marks_ = nullptr;  ///< marks held back while a run is placed (as_one_run)
  PointSet poles_, trees_;
  std::uint16_t next_instance_ = 1;
};

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

}  // namespace saloam
