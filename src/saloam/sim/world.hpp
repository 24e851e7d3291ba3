#pragma once
// A procedural street world built along a whole trajectory, for ray casting
// synthetic LiDAR scans. Everything is a function of the world position (and
// of time for the dynamic objects), never of the pass, so a place driven
// twice is the same place: loop closures in simulated data are real.
//
// World frame: the trajectory's frame (first LiDAR frame), z up. The ground
// sits `sensor_height` below the driven path.

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/types.hpp"
#include "saloam/sim/random.hpp"

namespace saloam {

enum class Shape : std::uint8_t { kBox, kCylinder, kEllipsoid };

/// Facade relief of a building side: recessed windows on a floor grid.
struct FacadePattern {
  float floor_height = 0;   ///< 0 = plain surface
  float window_spacing = 3;
  float window_width = 1.4f;
  float window_height = 1.5f;
  float recess = 0.25f;
  float glass_dropout = 0.5f;  ///< probability that a window returns nothing
};

/// One solid (or porous) object: a vertical prism/cylinder or an ellipsoid.
struct Primitive {
  Shape shape = Shape::kBox;
  std::uint16_t label = 0;
  std::uint16_t instance = 0;
  Eigen::Vector2f center{0, 0};
  float z_min = 0, z_max = 0;      ///< vertical extent (ellipsoid: its bounding slab)
  float cos_yaw = 1, sin_yaw = 0;  ///< box/ellipsoid orientation about z
  float half_x = 0, half_y = 0;    ///< box half extents; cylinder radius = half_x; ellipsoid semi-axes
  float remission = 0.3f;
  /// > 0: porous (foliage, chain-link): mean free path inside [m]; rays pass through sometimes.
  float mean_free_path = 0;
  float time_on = -std::numeric_limits<float>::infinity();  ///< present during [time_on, time_off)
  float time_off = std::numeric_limits<float>::infinity();
  FacadePattern facade;

  [[nodiscard]] bool present(double t) const { return t >= time_on && t < time_off; }
  /// Conservative 2D bounding radius around `center`.
  [[nodiscard]] float footprint_radius() const;
};

/// An object moving along the driven path: position is a function of time.
struct Agent {
  enum class Motion : std::uint8_t { kConstantSpeed, kLeadsEgo };
  Motion motion = Motion::kConstantSpeed;
  std::uint16_t label = 0;
  std::uint16_t instance = 0;
  double s_ref = 0;        ///< path arc length at t_ref (kConstantSpeed)
  double t_ref = 0;
  double speed = 0;        ///< signed speed along the path [m/s]
  double gap = 15;         ///< kLeadsEgo: mean distance ahead of the ego [m]
  double gap_amplitude = 5;
  double gap_period = 30;
  double gap_phase = 0;
  double lateral = 0;      ///< offset to the left of the path direction [m]; 0 = sidewalk (computed)
  int sidewalk_side = 0;   ///< persons: -1 right, +1 left sidewalk
  double t_begin = 0, t_end = 0;  ///< active time window
  float length = 4.4f, width = 1.8f, height = 1.5f;
  float remission = 0.3f;
};

/// Result of a ray cast.
struct RayHit {
  double range = std::numeric_limits<double>::infinity();
  std::uint16_t label = 0;
  std::uint16_t instance = 0;
  float remission = 0;
  bool hit = false;
};

struct WorldOptions {
  double sensor_height = 1.73;  ///< LiDAR above the road [m] (KITTI)
  double ground_cell = 1.0;     ///< ground raster resolution [m]
  double object_cell = 2.0;     ///< ray-casting grid resolution [m]
  double margin = 140.0;        ///< world extent beyond the path [m]
  double frame_period = 0.1;    ///< time between trajectory poses [s]
  bool dynamic_objects = true;
  /// A road on a hillside (the "hill-climb" preset, preset_on_hillside):
  /// across the road the ground tilts with each pose's roll (the road's
  /// cross-slope, up to kHillsideBankWidth either side of the path), and
  /// away from it, beyond kHillsideNear, it blends into the broad relief
  /// (the heights averaged over some +-50 m) by kHillsideFar: between two
  /// legs of a switchback at different heights the ground then slopes
  /// instead of stepping where the nearer leg changes. Off, the ground
  /// takes the height of the nearest path point everywhere, level across
  /// the road (KITTI trajectories and the other presets: their worlds stay
  /// as measured).
  bool hillside = false;
  static constexpr double kHillsideBankWidth = 12.0, kHillsideNear = 15.0, kHillsideFar = 45.0;  ///< [m]
};

/// Ground layout at one place, derived from the distance to the driven path.
struct GroundInfo {
  double height = 0;
  std::uint16_t label = 0;
  float remission = 0;
};

/// The driven path: ground points (sensor_height below the poses) at most
/// 0.5 m apart with their arc length, and the arc length at each trajectory
/// pose (the ego timeline). Built first (build_world), then handed to World.
struct WorldPath {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> s;      ///< arc length of points[i] [m]
  std::vector<double> ego_s;  ///< arc length of trajectory pose i [m]
  /// How much the ground rises per metre to the left of the path at
  /// points[i], from the roll of the poses about it (WorldOptions::hillside).
  std::vector<double> cross_slope;

  [[nodiscard]] double length() const { return s.empty() ? 0.0 : s.back(); }
  /// The point on the path at arc length `at` (clamped to the path): position
  /// (on the ground) and heading, smoothed over a few metres.
  void point(double at, Eigen::Vector3d& position, Eigen::Vector2d& direction) const;
};

/// The street world. build_world() makes it in three steps, each through
/// this interface: the path and the ground raster (the constructor), the
/// static objects and moving agents (add_object, add_agent), and last the
/// ray-casting grid over the static objects (index_objects).
class World {
 public:
  /// Street layout of one ground raster cell.
  struct Zone {
    float road_right = 2;  ///< road extent right of the path
    float road_left = 5;   ///< road extent left of the path (oncoming lane)
    float parking = 0;   ///< parking width beyond the road
    /// Width of the strip along each road edge, inside road_left/right and
    /// labelled road, where cars park at the curb (0 = none).
    float curb_parking = 0;
    float sidewalk = 3;  ///< sidewalk width (0 = rural, no curb)
    std::uint8_t verge = 0;  ///< 0 terrain, 1 paved (sidewalk), 2 other-ground
    [[nodiscard]] double road(int side) const { return side > 0 ? road_left : road_right; }
  };

  /// Within each tile of kRiseTile x kRiseTile raster cells, the ground
  /// rises at most Ground::rise[tile] per metre along any horizontal
  /// direction, plus steps of at most kGroundStep (curbs, zone edges).
  static constexpr int kRiseTile = 8;
  static constexpr double kGroundStep = 0.5;  ///< [m]
  /// Height of the curb (sidewalks and verges) and of parking lanes above
  /// the road surface [m].
  static constexpr double kCurbHeight = 0.13, kParkingRise = 0.02;

  /// The ground raster: nx x ny cells of options.ground_cell from `origin`
  /// (row-major, x fastest), with the distance and signed side to the path,
  /// the height, the bump and the zone of each cell, and per tile of
  /// kRiseTile cells a bound on the ground's rise and its highest point.
  struct Ground {
    Eigen::Vector2d origin{0, 0};
    int nx = 0, ny = 0;
    std::vector<float> distance, lateral, height, bump;
    int rise_nx = 0, rise_ny = 0;
    std::vector<float> rise;  ///< per tile: rise per metre
    std::vector<float> top;   ///< per tile: the highest the ground gets [m] (an upper bound)
    std::vector<Zone> zones;
  };

  /// An empty world (nothing to cast against).
  World() = default;
  /// A world of the driven path and the ground, without objects yet.
  World(const WorldOptions& options, std::uint64_t seed, WorldPath path, Ground ground);
  /// Adds a static object (before index_objects).
  void add_object(const Primitive& primitive) { primitives_.push_back(primitive); }
  void add_agent(const Agent& agent) { agents_.push_back(agent); }
  /// Builds the ray-casting grid over the static objects added so far.
  void index_objects();

  [[nodiscard]] const WorldOptions& options() const { return options_; }
  [[nodiscard]] std::uint64_t seed() const { return seed_; }
  [[nodiscard]] const Ground& ground() const { return ground_; }
  /// Index of the ground raster cell at (x, y) (clamped to the raster).
  [[nodiscard]] std::size_t cell_index(double x, double y) const;
  [[nodiscard]] Zone zone_at(double x, double y) const;
  /// Distance from (x, y) to the driven path (bilinear on the raster) [m].
  [[nodiscard]] double path_distance(double x, double y) const;
  /// Signed lateral offset from the driven path (positive = left of the
  /// direction of travel of the nearest path point).
  [[nodiscard]] double path_lateral(double x, double y) const;
  /// Distance beyond the edge of the road (negative inside the road). The
  /// road spans ~2 m to the right of the path and one or two lanes more to the
  /// left (right-hand traffic), over the whole trajectory.
  [[nodiscard]] double road_margin(double x, double y) const;
  [[nodiscard]] bool in_road(double x, double y) const { return road_margin(x, y) < 0.0; }
  /// Ground surface height and class at (x, y).
  [[nodiscard]] GroundInfo ground_at(double x, double y) const;
  [[nodiscard]] double ground_height(double x, double y) const;
  /// Where the LiDAR really is when the trajectory puts it at `pose_origin`:
  /// at the pose, unless that is not `sensor_height` - 0.5 m to + 0.8 m above
  /// the ground under it (a car stands on its wheels); then at the nearest
  /// bound. That happens only where the trajectory's height does not fit one
  /// ground surface (ground-truth height errors, e.g. KITTI 08); it is a
  /// function of the pose, so revisits stay consistent.
  [[nodiscard]] Eigen::Vector3d sensor_origin(const Eigen::Vector3d& pose_origin) const;

  [[nodiscard]] const std::vector<Primitive>& primitives() const { return primitives_; }
  [[nodiscard]] const std::vector<Agent>& agents() const { return agents_; }

  /// Dynamic objects as primitives at time t, those within `radius` of `near`.
  void agents_at(double t, const Eigen::Vector2d& near, double radius, std::vector<Primitive>& out) const;
  /// Pose of the point on the path at arc length s: position (on the ground) and heading.
  void path_point(double s, Eigen::Vector3d& position, Eigen::Vector2d& direction) const;
  /// Ego arc length at time t.
  [[nodiscard]] double ego_arc_length(double t) const;
  [[nodiscard]] double path_length() const { return path_.length(); }

  /// Where rays start and how high that is above the ground (positive =
  /// above), shared by every ray cast from there.
  struct RayOrigin {
    Eigen::Vector3d position;
    double clearance;
  };
  [[nodiscard]] RayOrigin ray_origin(const Eigen::Vector3d& position) const;
  /// Casts one ray (unit direction) against ground, static objects present at
  /// time t and the given dynamic primitives. `rng` drives porous surfaces.
  [[nodiscard]] RayHit cast_ray(const RayOrigin& origin, const Eigen::Vector3d& direction, double max_range, double t,
                                std::span<const Primitive> dynamic, Rng& rng) const;

 private:
  /// The ground's return `range` metres along the ray from `o` in direction `d`.
  [[nodiscard]] RayHit ground_hit(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double range) const;
  /// Where agent `a` stands at time t (ground-plane position [m]) and the
  /// path's direction there; false when it is not on the path then.
  bool agent_place(const Agent& a, double t, Eigen::Vector2d& xy, Eigen::Vector2d& direction) const;
  [[nodiscard]] double bilinear(const std::vector<float>& field, double x, double y) const;
  /// Distance, height and bump interpolated together, plus the cell index
  /// (the ray marcher's hot path: one set of weights for all three).
  struct FieldSample {
    double distance, height, bump;
    std::size_t cell;
  };
  [[nodiscard]] FieldSample sample(double x, double y) const;
  [[nodiscard]] GroundInfo ground_from(const FieldSample& s) const;
  /// The ray's first ground crossing, marched only as far as a caller needs it.
  class GroundMarch;

  WorldOptions options_;
  std::uint64_t seed_ = 0;
  WorldPath path_;
  Ground ground_;
  struct PackedCell {
    float distance, height, bump, pad;
  };
  std::vector<PackedCell> packed_;  ///< ground_.distance, height, bump interleaved
  // Static objects and their 2D grid (CSR).
  std::vector<Primitive> primitives_;
  int gx_ = 0, gy_ = 0;
  std::vector<std::uint32_t> cell_start_, cell_items_;
  std::vector<Agent> agents_;
};

/// Builds the world along the whole LiDAR trajectory (T_W<-L_i, 10 Hz).
World build_world(const std::vector<Pose>& lidar_trajectory, std::uint64_t seed, const WorldOptions& options = {});

}  // namespace saloam
