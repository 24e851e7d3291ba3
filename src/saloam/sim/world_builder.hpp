#pragma once
// Procedural construction of the street world along a trajectory (internal
// to sim/; build_world in world.hpp is the entry point). In parts, one file
// each, run in this order by build_world (world_builder.cpp):
//   world_ground.cpp      the driven path and the ground raster: road centre
//                         lines (with side streets), distance and side to
//                         the path, height, street layout (zones), bumps
//   world_buildings.cpp   buildings with their plots (front gardens,
//                         driveways, property lines)
//   world_objects.cpp     parked vehicles, street furniture, structures,
//                         moving agents
//   world_boundaries.cpp  hedges and fences along the street and the plots
//   world_vegetation.cpp  trees, bushes, shrub patches and verge beds
// Static objects are placed greedily with collision checks on a raster of
// occupied cells (so a revisited street is filled once, not twice); the
// placement helpers are here and in world_builder.cpp. Last comes the
// ray-casting grid (World::index_objects).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/types.hpp"
#include "saloam/sim/random.hpp"
#include "saloam/sim/world.hpp"

namespace saloam::world_building {

inline constexpr double kPi = 3.14159265358979323846;

// Open country (no sidewalks, few buildings) where the rural noise exceeds
// this: KITTI's sequences are mostly town and suburb.
inline constexpr double kRuralNoise = 0.78;

// Streets with cars parked along the curbs (where the parking noise exceeds
// this), the strip they take on each side [m] and the share of its length
// they fill.
inline constexpr double kCurbParkingNoise = 0.6;
inline constexpr float kCurbParkingWidth = 2.0f;
inline constexpr double kCurbParkedShare = 0.75;

// Objects stand at least this far off a road without sidewalk [m].
inline constexpr double kRoadsideMargin = 0.5;
// Hedges and fences along a street stand this far behind the sidewalk [m],
// and may come this close to it [m] where the sidewalk widens along them
// (other objects keep 0.1 m clear); a fence is checked and marked as this
// half-width [m] around its line.
inline constexpr double kLineGap = 0.12;
inline constexpr double kLineClearance = 0.0;
inline constexpr double kFenceCheckHalfWidth = 0.3;

// Seeds of the world's independent random streams (hashed with the world seed).
enum Salt : std::uint64_t {
  kSaltRoad = 101, kSaltParking, kSaltLot, kSaltSidewalk, kSaltVerge, kSaltRural, kSaltBump, kSaltBump2,
  kSaltBuildings, kSaltFences, kSaltTrees, kSaltPoles, kSaltCars, kSaltAgents, kSaltStructures, kSaltVerges
};

}  // namespace saloam::world_building

namespace saloam {

// Builds a World along a trajectory (build_world): the driven path and the
// ground raster as its own data, handed to World's constructor
// (take_world), then the objects into that world through its interface
// (place_objects).
class WorldBuilder {
 public:
  WorldBuilder(const WorldOptions& options, std::uint64_t seed) : options_(options), seed_(seed) {}

  /// A step between consecutive trajectory poses longer than this [m] is
  /// the jump between two passes through the world (SimulationOptions::passes), not a drive.
  static constexpr double kPassJump = 5.0;

  // ------------------------------------------------------------ ground (world_ground.cpp)
  void build_path(const std::vector<Pose>& trajectory);
  void build_ground();

  /// The world of the path and the ground built so far; the builder keeps
  /// the ground's raster geometry for placing the objects.
  World take_world();
  /// Every kind of object into `world` (take_world's), in placement order.
  void place_objects(World& world, double total_time);

 private:
  // ------------------------------------------------------------ objects, in placement order
  void place_buildings(double total_time);          // world_buildings.cpp
  void place_parked_vehicles(double total_time);    // world_objects.cpp
  void place_street_furniture();                    // world_objects.cpp
  void place_boundaries();                          // world_boundaries.cpp
  void place_trees();                               // world_vegetation.cpp
  void place_structures();                          // world_objects.cpp
  void plant_verges();                              // world_vegetation.cpp
  void place_agents(double total_time);             // world_objects.cpp

  // ------------------------------------------------------------ ground raster steps (world_ground.cpp)
  /// Raster extent (the path's bounding box plus the margin) and size.
  void lay_out_raster();
  /// Road centre lines: the driven path plus side streets branching off it
  /// (dead-end stubs, so that the street has open intersections).
  void road_centre_lines(std::vector<Eigen::Vector3d>& centres, std::vector<Eigen::Vector2d>& dirs);
  void add_side_streets(std::vector<Eigen::Vector3d>& centres, std::vector<Eigen::Vector2d>& dirs);
  /// Distance to the nearest centre-line sample per cell, and that sample.
  std::vector<std::int32_t> nearest_centres(const std::vector<Eigen::Vector3d>& centres);
  void side_of_path(const std::vector<std::int32_t>& source, const std::vector<Eigen::Vector3d>& centres,
                    const std::vector<Eigen::Vector2d>& dirs);
  void ground_heights(const std::vector<std::int32_t>& source, const std::vector<Eigen::Vector3d>& centres);
  [[nodiscard]] World::Zone street_layout(const Eigen::Vector2d& c) const;
  [[nodiscard]] float bump_at(const Eigen::Vector2d& c) const;
  void street_zones_and_bumps();
  void bound_ground_rise();
  void box_blur(std::vector<float>& f, int radius) const;
  /// Centre of raster cell (ix, iy) and its index.
  [[nodiscard]] Eigen::Vector2d cell_centre(int ix, int iy) const {
    const double size = options_.ground_cell;
    return {ground_.origin.x() + (ix + 0.5) * size, ground_.origin.y() + (iy + 0.5) * size};
  }
  [[nodiscard]] std::size_t cell(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(ground_.nx) + static_cast<std::size_t>(ix);
  }

  // ------------------------------------------------------------ placement helpers (world_builder.cpp)
  /// How far behind the street's edge (street_edge) a hedge, fence or bed
  /// along it starts at the nearest: just behind the sidewalk, or beyond a
  /// country road's margin (rect_free).
  static double line_gap(bool rural) {
    return rural ? world_building::kRoadsideMargin + 0.02 : world_building::kLineGap;
  }
  /// Lateral distance from the path to the back of the sidewalk on one side.
  [[nodiscard]] double street_edge(const Eigen::Vector2d& p, int side) const;
  [[nodiscard]] bool inside_grid(const Eigen::Vector2d& p) const;

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
                 bool road_only) const;
  void mark_rect(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy);

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
  bool clear_of_road(const Eigen::Vector2d& c, double r, double clearance) const;
  bool disc_free(const Eigen::Vector2d& c, double r, double road_clearance) const;

  Primitive box(std::uint16_t label, const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy,
                double z0, double z1, double remission) const;
  static Primitive cylinder(std::uint16_t label, const Eigen::Vector2d& c, double radius, double z0, double z1,
                            double remission);
  [[nodiscard]] double ground(const Eigen::Vector2d& p) const { return w_->ground_height(p.x(), p.y()); }

  // Walks the path in steps, calling f(position, direction, s).
  template <class F>
  void walk(double start, F&& f) const {
    double s = start;
    const double len = w_->path_length();
    while (s < len) {
      Eigen::Vector3d pos;
      Eigen::Vector2d dir;
      w_->path_point(s, pos, dir);
      const double advance = f(pos.head<2>(), dir, s);
      s += std::max(0.5, advance);
    }
  }

  // ------------------------------------------------------------ buildings and plots (world_buildings.cpp)
  /// A building plot along the street (building_plot).
  struct Plot {
    Eigen::Vector2d p, axis, mleft;  ///< where along the path, the facade's direction, towards the plot
    int side;
    double length, depth, edge, setback;
  };
  /// One building with its plot at path point p on one side; the advance along the path, or 0 if none fits.
  double building_plot(const Eigen::Vector2d& p, const Eigen::Vector2d& dir, int side, Rng& rng, double total_time);
  /// Between the street and the house: property line, garden, driveway car, foundation planting.
  void front_garden(const Plot& plot, Rng& rng, double total_time);
  void driveway_car(const Plot& plot, Rng& rng, double total_time);
  void gap_planting(const Plot& plot, double gap, Rng& rng);
  void add_building(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy, double height, Rng& rng);
  double lowest_ground(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double hx, double hy) const;
  /// Along a property line that starts at `front` (the back of the
  /// sidewalk; `away` points from the street into the plot): a hedge, or a
  /// fence with shrubs or a hedge behind it, each as close to the sidewalk
  /// as the clearance check allows (kLineGap).
  void property_line(const Eigen::Vector2d& front, const Eigen::Vector2d& axis, const Eigen::Vector2d& away,
                     double half_length, Rng& rng);

  // ------------------------------------------------------------ hedges and fences (world_boundaries.cpp)
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
                 double height, Rng& rng);
  bool add_hedge_piece(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, double half_width,
                       double height, Rng& rng);
  /// What a fence is made of: boards or railings, or chain-link the beam partly passes.
  struct FenceStyle {
    bool chain_link = false;
    double height = 1.5, remission = 0.3;
  };
  static FenceStyle fence_style(double height, double chain_link, Rng& rng);
  bool add_fence(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, double height,
                 double chain_link, Rng& rng);
  bool add_fence_piece(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, const FenceStyle& style);
  /// Shrubs or a hedge just behind a fence, taller than it now and then.
  void planting_behind(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, const Eigen::Vector2d& away,
                       double half_length, Rng& rng);

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
        w_->path_point(s + (2 * k + 1) * half, pos, dir);
        const Eigen::Vector2d away = side * Eigen::Vector2d(-dir.y(), dir.x());
        const double edge = street_edge(pos.head<2>() + away * 7.0, side);
        const RunPiece piece{pos.head<2>() + away * (edge + offset), dir, away, half};
        if (place(piece)) placed.push_back(piece);
      }
    });
    return placed;
  }
  /// One stretch of hedge or fence along one side of the street from arc
  /// length s; the advance along the path.
  double boundary_run(const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double s, int side, Rng& rng);

  // ------------------------------------------------------------ vegetation (world_vegetation.cpp)
  void add_tree(const Eigen::Vector2d& c, double crown, Rng& rng);
  /// A low, wide mound of shrubs on open ground (a flattened ellipsoid).
  void add_shrub_patch(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double rx, double ry, double height, Rng& rng);
  void add_bush(const Eigen::Vector2d& c, double r, Rng& rng);
  void place_street_trees();
  void scatter_trees();

  // ------------------------------------------------------------ vehicles (world_objects.cpp)
  void add_vehicle(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, std::uint16_t label, double length,
                   double width, double height, Rng& rng, double total_time);
  static void vehicle_dims(Agent& a, Rng& rng);

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
  static bool far_from(const PointSet& set, const Eigen::Vector2d& c, double min_dist);

  WorldOptions options_;
  std::uint64_t seed_;
  WorldPath path_;        ///< built by build_path, then the world's
  World::Ground ground_;  ///< built by build_ground, then the world's
  /// The ground raster's geometry (ground_'s origin, nx, ny), kept for the
  /// raster of occupied cells once the ground is the world's.
  Eigen::Vector2d origin_{0, 0};
  int nx_ = 0, ny_ = 0;
  World* w_ = nullptr;  ///< the world the objects go into (place_objects)
  std::vector<std::uint8_t> occupied_;
  struct MarkedRect {
    Eigen::Vector2d c, axis;
    double hx, hy;
  };
  std::vector<MarkedRect>* run_marks_ = nullptr;  ///< marks held back while a run is placed (as_one_run)
  PointSet poles_, trees_;
  std::uint16_t next_instance_ = 1;
};

}  // namespace saloam
