#pragma once
// The configuration of the whole system: plain structs with documented
// defaults (the paper's Table I where it gives one), plus one generic field
// visitor per struct so that YAML loading, saving and `--set key=value`
// overrides share one list of names, docs and valid ranges. To add a
// parameter: add the member with its default and one line to the struct's
// `visit_fields` (name, member, doc, range; bool fields have no range).
// Loading and overrides reject values outside a field's range, and
// combinations that contradict each other (see validate_config).
//
// Keys are "<section>.<field>", e.g. "odometry.alpha". Table I symbols are
// named in each comment.

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/gravity_config.hpp"

namespace saloam {

/// Per-class values keyed by SemanticKITTI class name ("road", "pole", ...);
/// the key "default" applies to classes not listed.
using ClassValueMap = std::map<std::string, double>;

/// Value of `map` for a raw class id, falling back to map["default"], then to `fallback`.
double class_value(const ClassValueMap& map, std::uint16_t raw_id, double fallback);

/// Valid values of a numeric field: lo <= x <= hi. An infinite hi admits
/// infinity (".inf"), for fields where it means "off" or "never".
struct Range {
  double lo;
  double hi;
};
/// Valid values of a numeric field: finite x >= lo.
struct AtLeast {
  double lo;
};
/// Valid values of a numeric field: finite x > lo (sizes, scales, durations).
struct Above {
  double lo;
};
/// Valid values of a field: one of those listed (strings or integers).
template <class T>
struct OneOf {
  OneOf(std::initializer_list<T> listed) : values(listed) {}
  std::vector<T> values;
};
/// Every value of the field's type is valid (free text, a seed).
struct Any {};

/// Infinity, the upper bound of a Range that admits ".inf".
inline constexpr double kInf = std::numeric_limits<double>::infinity();
/// Neighbours the registration fits a line or plane to at most (its kMaxNeighbours).
inline constexpr int kMaxFitNeighbours = 32;

/// LOAM feature extraction (paper Sec. III-B, Eq. 1).
struct FeatureConfig {
  /// alpha: roughness threshold; c > alpha edge, c < alpha planar. c is Eq. 1
  /// without its 1/(|S| ||X||) normalisation, squared [m^2] (A-LOAM/F-LOAM form,
  /// for which 0.1 is the customary value).
  double alpha = 0.1;
  int num_sectors = 6;          ///< N_r: sectors per ring
  int edges_per_sector = 20;    ///< N_e: sharpest points kept as edges per sector
  int planars_per_sector = 50;  ///< N_p: flattest points kept as planars per sector
  int roughness_half_window = 5;  ///< neighbours on each side in Eq. 1 (LOAM uses 5)
  /// With labels, the roughness above which a point of a ground class (road,
  /// sidewalk, parking, terrain, other-ground) may be an edge feature; alpha
  /// or less: like any class, .inf: never (the ground gives only planars, as
  /// in LeGO-LOAM; the default). The ground's rough points are range noise
  /// and the rings' footprints next to other objects: they move with the
  /// sensor, and as edges they shortened every route (docs/odometry.md,
  /// "Scale bias").
  double ground_edge_alpha = kInf;
  /// [m] Without labels, points less than this above the ground are no edge
  /// features (label-free twin of ground_edge_alpha = .inf). The ground's
  /// height is the median height of the lowest ring's returns within 20 m.
  /// Without it, the rings' footprints on the ground become edges; they move
  /// with the sensor, and with 16 beams they held a moving start back to a
  /// tenth of its speed (docs/odometry.md, "Scale bias"). 0: off.
  double unlabelled_ground_margin = 0.3;
  /// With labels, an edge feature of a pole or tree trunk stands for the
  /// object's axis (ThinObjectAxis): the returns on a round object's near side
  /// move with the viewpoint and shorten every route (docs/odometry.md,
  /// "Scale bias").
  bool thin_object_axes = true;
  /// [m] a pole or trunk crossing wider than this radius is no thin object
  /// (it merges with another surface): no edge feature.
  double thin_object_max_radius = 0.5;
  double min_range = 2.5;       ///< [m] closer returns are ignored (vehicle body)
  double max_range = 120.0;     ///< [m]
  /// Beams of the sensor: 0 = the number of beam_elevations_deg, or without
  /// those 64/32/16 detected from the data (the HDL-64E, HDL-32E or VLP-16
  /// layout that fits the elevation range).
  int num_beams = 0;
  /// Elevation [deg] of each laser, top first, from the sensor profile
  /// (--sensor, config/sensors/*.yaml): rings of scans without a ring field
  /// that are not stored laser by laser are the nearest laser's. Empty: the
  /// layout of num_beams.
  std::vector<double> beam_elevations_deg;
  /// Take rings from the storage order when the scan is stored ring by ring
  /// (KITTI, simulator), else from the elevation angle. The order stays exact
  /// when points were motion-compensated; the elevation then does not.
  bool ring_from_point_order = true;
  /// Seconds into the 0.1 s sweep that a scan's pose refers to: 0 for sweep
  /// start (the simulator), 0.05 for real KITTI (pose when facing forward).
  double pose_time_in_sweep = 0.0;
  double sweep_duration = 0.1;  ///< [s] one LiDAR revolution
  /// Azimuth [deg] where a sweep starts (atan2(y, x) in the LiDAR frame);
  /// 180 = behind the car, as KITTI's HDL-64E and the simulator.
  double sweep_start_azimuth_deg = 180.0;
  /// Rotation sense seen from above: true = clockwise (decreasing azimuth, Velodyne).
  bool sweep_clockwise = true;
};

/// Scan-to-local-map registration (paper Sec. III-B, Eq. 2).
struct OdometryConfig {
  FeatureConfig features;
  GravityConfig gravity;
  /// N_m: a map voxel that none of the last N_m frames observed leaves the
  /// map. Table I has 20 (config/paper.yaml); 40 frames, about 40 m of road,
  /// drift less with first points kept (measured in docs/odometry.md).
  int local_map_frames = 40;
  /// The point a map voxel keeps when observed again: "first" (the map stays
  /// anchored where it was first registered) or "newest" (the map follows the
  /// latest frames; the paper's map of the last N_m frames). See MapVoxelPoint.
  std::string local_map_point = "first";
  int edge_neighbours = 5;       ///< N_ne: map points fitted to a line per edge feature
  int planar_neighbours = 5;     ///< N_np: map points fitted to a plane per planar feature
  /// Tolerance of the semantic plane constraint (not a Table I parameter;
  /// Table I's sigma is the drift rate loop.sigma). A plane of a ground class
  /// is kept only if |n . up| >= 1 - tolerance (normal near vertical), one of
  /// building/fence only if |n . up| <= tolerance (normal near horizontal);
  /// up is gravity's (odometry.gravity).
  double plane_normal_tolerance = 0.05;
  /// A map line (edge feature's fitted neighbours) whose unit direction d
  /// rises less than this, |d . up| < level_line_max_rise, is a level line and
  /// constrains the feature only across it horizontally (the vertical plane
  /// through it), not in height. A level line is mostly one ring's footprint
  /// seen by several frames, whose height moves with the sensor
  /// (z = range * tan(elevation)): fitted as a line, it pulls the pitch, most
  /// with 16 beams, with or without labels (docs/odometry.md, "Level edge
  /// lines": 0.5, lines rising less than 30 degrees). 0: off, every line a
  /// line.
  double level_line_max_rise = 0.5;
  bool use_semantics = true;     ///< false: label-agnostic FLOAM-style baseline
  /// Match within groups of classes that networks confuse and that share a
  /// geometry (ground, building+fence, pole-like, vehicles; see class_group())
  /// instead of strictly within one class. Voxel size, weight and plane
  /// constraint of a group are those of its representative (road, building,
  /// pole, car).
  /// On by default: with noisy labels strict per-class matching splits one
  /// surface over several submaps (docs/odometry.md).
  bool match_class_groups = true;
  /// Undistort scans with the constant-velocity motion (internally to
  /// mid-sweep). On by default: it halves the error of real KITTI scan pairs
  /// and of simulated runs (docs/odometry.md).
  bool deskew = true;
  int max_iterations = 10;       ///< Gauss-Newton iterations per outer loop
  int outer_iterations = 3;      ///< re-association rounds (beyond, only while far off: far_outer_iterations)
  /// A round that moved the pose less than this (and after which the scan
  /// did not need de-skewing again) ends the re-association early (0 =
  /// always all rounds): most frames converge in fewer rounds, at nearly the
  /// same accuracy (docs/odometry.md).
  double reassociation_min_translation = 0.01;  ///< [m]
  double reassociation_min_rotation_deg = 0.1;  ///< [deg]
  double robust_kernel_scale = 0.1;  ///< [m] Huber scale of the residuals
  /// [m] farthest map neighbour accepted; also the cell size of the local
  /// map's neighbour grid.
  double max_correspondence_distance = 1.0;
  double voxel_size = 0.4;       ///< [m] voxel size without semantics (and default class size)
  /// Semantic downsampling: per-class voxel size [m]. Small objects (pole,
  /// trunk, traffic-sign) keep their points at 0.1 m; large classes use the
  /// label-agnostic size: coarser large classes lost to --no-semantics
  /// (docs/odometry.md).
  ClassValueMap class_voxel_size{{"default", 0.4}, {"pole", 0.1}, {"trunk", 0.1}, {"traffic-sign", 0.1}};
  /// w^l of Eq. 2: per-class residual weights. Foliage is porous: a beam
  /// ends inside the crown at a depth that changes with the viewpoint, so its
  /// "surfaces" move between scans in a way its residual variance (which the
  /// adaptive weights follow) does not show; its prior weight is halved.
  /// Lower drift with network, emulated and ground-truth labels on most
  /// sequences measured; equal weights in config/paper.yaml
  /// (docs/odometry.md, "Per-class weights").
  ClassValueMap class_weight{{"default", 1.0}, {"vegetation", 0.5}};
  /// With semantics, scale each class's w^l by the pooled residual variance
  /// over the class's own (inverse-variance weighting, estimated from the
  /// last frames' fits): the "automatic way for weights setting" the paper
  /// leaves to future work. On by default: lower drift on every simulated
  /// sequence measured (docs/odometry.md, "Per-class weights").
  bool adaptive_class_weights = true;
  int threads = 1;               ///< worker threads for association (0 = all cores)
  /// A registration direction whose eigenvalue of the Hessian per
  /// correspondence (rotations as the displacement they cause at the
  /// features' RMS range; 1 = every residual constrains it fully) is below
  /// this is degenerate: the pose keeps the constant-velocity prediction
  /// along it, and the frame is counted and reported (0 = off). Truly
  /// unconstrained directions sit near 0; 64-beam street scans reach 0.012
  /// with every direction measured (docs/reliability.md).
  double degeneracy_eigenvalue = 0.005;
};

/// Semantic Scan Context (Li et al., "SSC: Semantic Scan Context for
/// Large-Scale Place Recognition", IROS 2021), the "ssc" loop detector. The
/// defaults are the paper's (its public code's): 24 rings x 360 sectors over
/// 5..50 m, 360 key-point sectors, 100 ICP iterations, 3 m gate, 5 m cap.
struct SscConfig {
  int rings = 24;                ///< rings of the descriptor between inner_radius and outer_radius
  int sectors = 360;             ///< sectors of the descriptor (1 degree each)
  double inner_radius = 5.0;     ///< [m] horizontal range where the descriptor starts
  double outer_radius = 50.0;    ///< [m] horizontal range where the descriptor ends
  int key_sectors = 360;         ///< sectors of the key-point projection used for the alignment
  int icp_iterations = 100;      ///< at most this many iterations of the 2D ICP of the alignment
  int icp_window = 10;           ///< [sectors] correspondences are searched this far either side
  double icp_gate = 3.0;         ///< [m] a correspondence farther than this in x or y is ignored
  /// [m] an alignment translating more than this in x or y is not trusted:
  /// the translation falls back to zero (the yaw stays).
  double max_translation = 5.0;
  /// [m] side of the square x-y cells that thin each scan before it is stored
  /// (one point per cell, of its highest-priority class); the descriptor of the
  /// aligned candidate is built from these points.
  double cell_size = 0.5;
};

/// Loop closure (paper Sec. III-C): candidates (Eq. 3), similarity scoring,
/// geometric verification by the semantic-assisted ICP.
struct LoopClosureConfig {
  /// Place-recognition scorer: "sgpr" (the paper's), "scancontext",
  /// "hybrid" (mean of SGPR and Scan Context scores) or "ssc" (Semantic Scan
  /// Context; needs labels). The default is the one measured best on
  /// loop closure (docs/loop_closure.md): the pretrained SGPR weights
  /// transfer poorly to simulated scans.
  std::string detector = "scancontext";
  /// sigma: odometry drift rate of Eq. 3 (search radius per metre travelled).
  /// Table I's 0.05 budgets for ~1 % drift; this odometry drifts ~0.1 %, and
  /// a wider radius only admits look-alike places (docs/loop_closure.md).
  /// config/paper.yaml keeps 0.05.
  double sigma = 0.01;
  double delta_min = 15.0;    ///< delta_min [m]: smallest search radius of Eq. 3
  double delta_max = 100.0;   ///< delta_max [m]: largest search radius of Eq. 3
  int num_candidates = 64;    ///< N_candi: at most this many candidates per query, drawn at random
  double zeta = 0.95;         ///< zeta: SGPR score threshold (score in (0, 1))
  /// Scan Context score threshold (score = 1 - column-shift distance);
  /// also used by "hybrid" for the mean of both scores.
  double scancontext_zeta = 0.6;
  /// Semantic Scan Context score threshold (score = fraction of the occupied
  /// cells whose classes agree after the alignment). Scores are low on noisy
  /// labels: 0.2 is near place-eval's max-F1 threshold (docs/loop_closure.md).
  double ssc_zeta = 0.2;
  int num_loop = 5;           ///< N_loop: best-scoring pairs (score > threshold) that go on to verification
  /// [m] Beyond the paper: the candidate nearest to the query by the current
  /// estimate is verified too when nearer than this, whatever its score
  /// (0 = off).
  double proximity_radius = 0.0;
  /// [m] Beyond the paper: the query keyframe is also described as seen from
  /// this far to either side of the sensor, as localize.lateral_query_offset
  /// (a reverse revisit in the other lane; 0 = off). Off by default: it
  /// closed no revisited stretch more, at two more descriptors per search
  /// (docs/loop_closure.md).
  double lateral_query_offset = 0.0;
  /// delta_r: threshold on the ICP loss r of Eq. 2 (the weighted sum of
  /// point-to-line and point-to-plane distances [m]) at the registered pose.
  /// Depends on the number of features per scan; used when
  /// `acceptance` = "loss".
  double delta_r = 100.0;
  /// Which verification test accepts a loop: "normalized" (mean residual,
  /// inlier fraction, degeneracy; independent of the scan's feature count)
  /// or "loss" (the paper's r < delta_r). Both are computed and written to
  /// loops.csv either way. The normalized thresholds below accept no false
  /// and the most true candidates of the 487 verified on simulated 00, 05, 08
  /// (docs/loop_closure.md); no delta_r does both.
  std::string acceptance = "normalized";
  double max_mean_residual = 0.05;     ///< [m] normalized test: mean |residual| of the inliers
  double min_inlier_fraction = 0.40;   ///< normalized test: features with a correspondence closer than inlier_distance
  double inlier_distance = 0.2;        ///< [m] a correspondence closer than this is an inlier
  /// Degeneracy check: smallest eigenvalue of the translation block of the
  /// registration Hessian per correspondence (1 = every residual constrains
  /// that direction fully; a straight road without cross structure gives ~0).
  double min_translation_eigenvalue = 0.05;
  /// Uniqueness test: a distinct fit (> 0.5 m or 2 deg away) found from
  /// starts 1.5 and 3 m along the least constrained direction may have at
  /// most this fraction of the best fit's inliers; .inf = off (the extra fits
  /// are then skipped). Off by default: along straight streets true loops
  /// have second-best fits nearly as good (docs/loop_closure.md).
  double max_runner_up_ratio = std::numeric_limits<double>::infinity();
  /// [m] Frames travelled less than this before the query are not
  /// candidates: a loop needs the vehicle to leave the place and come back.
  double exclude_recent_distance = 50.0;
  int submap_half_width = 10;  ///< keyframes on each side of the candidate forming its submap
  /// [m] After an accepted loop the next search waits this much travel:
  /// consecutive queries would only confirm the same constraint, at the
  /// cost of a verification and an optimisation each (10 vs 20 m measured
  /// in docs/loop_closure.md).
  double search_interval_after_loop = 20.0;
  std::uint64_t seed = 42;     ///< random generator of the N_candi draw (deterministic output)
  std::string sgpr_model;      ///< SGPR weights (.sgw); required when the detector uses SGPR
  SscConfig ssc;               ///< descriptor and alignment of the "ssc" detector
};

/// The SLAM back end: keyframes, pose graph and global map.
struct SlamConfig {
  double keyframe_distance = 1.0;   ///< [m] travel that makes a new keyframe (graph node, place descriptor)
  double keyframe_angle_deg = 10.0; ///< [deg] rotation that makes a new keyframe
  /// Information of an edge = scale * H / N, with H the registration's
  /// Gauss-Newton Hessian and N its correspondence count: correspondences
  /// are correlated, so each edge counts as `scale` [1/m^2] worth of
  /// independent unit residuals (1e4: 100 residuals of 0.1 m).
  double information_scale = 1e4;
  /// Cauchy scale of loop edges in the second, robust phase of each
  /// optimisation [whitened units, i.e. standard deviations]: a loop that
  /// still disagrees by many times this after the plain solve loses its weight.
  double loop_robust_scale = 10.0;
  int max_iterations = 10;          ///< Levenberg-Marquardt iterations per phase of an optimisation
  double map_voxel_size = 0.25;     ///< [m] global semantic map resolution
  int map_frame_step = 2;           ///< every n-th frame goes into the global map
};

/// Localisation in a saved map (`saloam localize`, docs/map_format.md):
/// relocalisation by place recognition and the loop closure's verification
/// (loop.*), then tracking against the map with the odometry between.
struct LocalizeConfig {
  /// [m] travel between relocalisation attempts while not placed (each
  /// describes the scan and scores it against every map keyframe).
  double relocalize_interval = 2.0;
  /// A relocalisation is believed only when this many later fixes agree
  /// with it: tracking registrations, `confirm_interval` m apart, started at
  /// the pose the odometry predicts from it and passing the loop closure's
  /// acceptance test.
  int confirmations = 2;
  double confirm_interval = 1.0;  ///< [m]
  /// Uniqueness of a place found with no prior (a search of the whole map:
  /// at the start, or after the odometry fallback ran out): the candidate's
  /// fit is refused when a distinct fit,
  /// started 1.5 and 3 m along its least constrained direction, reaches this
  /// fraction of its inliers (loop.max_runner_up_ratio's test). Along a
  /// street that the map cannot tell from another, such a second solution is
  /// nearly as good. It decides under the normalized acceptance test (the
  /// default loop.acceptance), not under the loss test. .inf = off.
  double max_runner_up_ratio = 0.9;
  /// [m] Place recognition describes the scan also as seen from this far
  /// to either side of the sensor (0: only from the sensor). Scan Context
  /// compares scans taken from one spot; a run in the opposite lane, or in
  /// the lane beside the mapped one, is about a lane width from where the
  /// map's scans were taken.
  double lateral_query_offset = 3.2;
  /// [m] map keyframes whose position lies within this of the predicted pose
  /// form the tracking submap.
  double track_radius = 40.0;
  /// [m] keyframes of the tracking submap are at least this far apart (the
  /// map's keyframes overlap; fewer make the submap cheaper).
  double submap_spacing = 2.0;
  /// [m] the tracking submap is rebuilt when the pose has moved this far
  /// from where it was built.
  double submap_rebuild_distance = 8.0;
  /// Register every n-th frame against the map; the odometry carries the
  /// frames between.
  int track_every = 2;
  /// A tracking fit is used when at least this fraction of the scan's
  /// features are inliers (closer than loop.inlier_distance) ...
  double track_min_inlier_fraction = 0.3;
  /// ... and it moves the odometry's prediction by at most this [m] / [deg].
  double track_max_correction = 1.0;
  double track_max_correction_deg = 3.0;
  /// [m] travel without a usable fit after which the run says it has left
  /// the mapped area and goes on with the odometry alone.
  double leave_after = 15.0;
  /// [m] travel on the odometry alone after the last fix beyond which frames
  /// are no longer placed (marked, no pose) until the run relocalises.
  double max_odometry_distance = 300.0;
  /// Map keyframes whose features are kept in memory at once (the rest are
  /// read again from the map when needed).
  int cached_keyframes = 400;
};

/// In-process semantic segmentation of raw scans (`--segment`; the first
/// box of the paper's Fig. 2): the model, and the pipeline stage that runs it
/// beside the odometry.
struct SegmentationConfig {
  /// Model description (.yaml, docs/segmentation.md); empty: the shipped
  /// models/segmenter/saloam.yaml. `--segmenter FILE` overrides it.
  std::string model;
  /// Scans segmented at once, each on a thread of its own (one intra-op
  /// thread each: labels do not depend on this number).
  int workers = 1;
  /// Scans segmented ahead of the consumer (odometry, SLAM).
  int lookahead = 4;
};

struct SaloamConfig {
  OdometryConfig odometry;
  LoopClosureConfig loop;
  SlamConfig slam;
  SegmentationConfig segmentation;
  LocalizeConfig localize;
};

/// Calls v(name, member, description, range) for every field; range is the
/// set of valid values (Range, AtLeast, Above, OneOf, Any; for a ClassValueMap
/// the range of each value). bool fields take no range: v(name, member, description).
template <class Visitor>
void visit_fields(FeatureConfig& c, Visitor&& v) {
  v("alpha", c.alpha, "alpha: roughness threshold edge/planar [m^2, unnormalised Eq. 1]", Above{0});
  v("num_sectors", c.num_sectors, "N_r: sectors per ring", AtLeast{1});
  v("edges_per_sector", c.edges_per_sector, "N_e: edge features per sector", AtLeast{1});
  v("planars_per_sector", c.planars_per_sector, "N_p: planar features per sector", AtLeast{1});
  v("ground_edge_alpha", c.ground_edge_alpha, "with labels, min roughness of a ground edge (.inf: none)", Range{0, kInf});
  v("unlabelled_ground_margin", c.unlabelled_ground_margin, "[m] without labels, points this close above the ground are no edges (0: off)", Range{0, 5});
  v("thin_object_axes", c.thin_object_axes, "with labels, pole and trunk edges stand for the object's axis");
  v("thin_object_max_radius", c.thin_object_max_radius, "[m] widest pole or trunk crossing kept as an edge", Range{0.01, 5});
  v("roughness_half_window", c.roughness_half_window, "ring neighbours each side in Eq. 1", AtLeast{1});
  v("min_range", c.min_range, "min range [m]", AtLeast{0});
  v("max_range", c.max_range, "max range [m]", Above{0});
  v("num_beams", c.num_beams, "beams (0 = beam_elevations_deg's, else detect 64/32/16)", Range{0, 1024});
  v("beam_elevations_deg", c.beam_elevations_deg, "[deg] laser elevations, top first (--sensor; [] = layout of num_beams)",
    Range{-90, 90});
  v("ring_from_point_order", c.ring_from_point_order, "rings from storage order when it is ring by ring");
  v("pose_time_in_sweep", c.pose_time_in_sweep, "[s] instant of the sweep a pose refers to", AtLeast{0});
  v("sweep_duration", c.sweep_duration, "[s] one revolution", Above{0});
  v("sweep_start_azimuth_deg", c.sweep_start_azimuth_deg, "[deg] azimuth where a sweep starts", Range{-360, 360});
  v("sweep_clockwise", c.sweep_clockwise, "sweep turns clockwise seen from above");
}

template <class Visitor>
void visit_fields(GravityConfig& c, Visitor&& v) {
  v("mount_rpy_deg", c.mount_rpy_deg, "[deg] R_base<-sensor as roll pitch yaw ([] = not given: estimate or assume)",
    Range{-360, 360});
  v("use_imu", c.use_imu, "without a mount, take up from the sensor's own IMU at rest when the source has one");
  v("estimate", c.estimate, "without a mount or IMU, estimate up from the scans (false: the sensor's z is up)");
  v("refine_every_frames", c.refine_every_frames, "scans looked at every this many frames to refine up", AtLeast{1});
  v("mount_warning_deg", c.mount_warning_deg, "[deg] warn when the scans' up differs from the mount's by more",
    Range{0, 180});
}

template <class Visitor>
void visit_fields(OdometryConfig& c, Visitor&& v) {
  v("local_map_frames", c.local_map_frames, "N_m: frames in the local map", AtLeast{1});
  v("local_map_point", c.local_map_point, "point a map voxel keeps when observed again", OneOf{"first", "newest"});
  v("edge_neighbours", c.edge_neighbours, "N_ne: neighbours per edge feature", Range{2, kMaxFitNeighbours});
  v("planar_neighbours", c.planar_neighbours, "N_np: neighbours per planar feature", Range{3, kMaxFitNeighbours});
  v("plane_normal_tolerance", c.plane_normal_tolerance, "plane constraint: tolerance on |n . up|", Range{0, 1});
  v("level_line_max_rise", c.level_line_max_rise,
    "map lines with |d . up| below this constrain only horizontally (0: off)", Range{0, 1});
  v("use_semantics", c.use_semantics, "semantic assistance on/off");
  v("match_class_groups", c.match_class_groups, "match within class groups instead of single classes");
  v("deskew", c.deskew, "constant-velocity de-skewing");
  v("max_iterations", c.max_iterations, "Gauss-Newton iterations", AtLeast{1});
  v("outer_iterations", c.outer_iterations, "re-association rounds (at most)", AtLeast{1});
  v("reassociation_min_translation", c.reassociation_min_translation, "[m] smaller pose change ends re-association", AtLeast{0});
  v("reassociation_min_rotation_deg", c.reassociation_min_rotation_deg, "[deg] smaller rotation ends re-association", AtLeast{0});
  v("robust_kernel_scale", c.robust_kernel_scale, "[m] robust kernel scale", Above{0});
  v("max_correspondence_distance", c.max_correspondence_distance, "[m] max neighbour distance", Above{0});
  v("voxel_size", c.voxel_size, "[m] voxel size (label-agnostic)", Above{0});
  v("class_voxel_size", c.class_voxel_size, "[m] per-class voxel size", Above{0});
  v("class_weight", c.class_weight, "w^l: per-class residual weight", AtLeast{0});
  v("adaptive_class_weights", c.adaptive_class_weights, "scale w^l by inverse residual variance per class");
  v("degeneracy_eigenvalue", c.degeneracy_eigenvalue, "below it a registration direction is degenerate (0: off)", Range{0, 1});
  v("threads", c.threads, "threads (0 = all cores)", AtLeast{0});
}

template <class Visitor>
void visit_fields(LoopClosureConfig& c, Visitor&& v) {
  v("detector", c.detector, "place-recognition scorer", OneOf{"sgpr", "scancontext", "hybrid", "ssc"});
  v("sigma", c.sigma, "sigma: odometry drift rate of Eq. 3 [m per m travelled]", AtLeast{0});
  v("delta_min", c.delta_min, "delta_min [m]: min search radius of Eq. 3", AtLeast{0});
  v("delta_max", c.delta_max, "delta_max [m]: max search radius of Eq. 3", Above{0});
  v("num_candidates", c.num_candidates, "N_candi: candidates per query (random draw beyond)", AtLeast{1});
  v("zeta", c.zeta, "zeta: SGPR score threshold", Range{0, 1});
  v("scancontext_zeta", c.scancontext_zeta, "Scan Context (and hybrid) score threshold", Range{0, 1});
  v("ssc_zeta", c.ssc_zeta, "Semantic Scan Context score threshold", Range{0, 1});
  v("num_loop", c.num_loop, "N_loop: best pairs verified per query", AtLeast{1});
  v("proximity_radius", c.proximity_radius, "[m] also verify the nearest candidate within this (0 = off)", AtLeast{0});
  v("lateral_query_offset", c.lateral_query_offset,
    "[m] place recognition also from this far to either side (another lane; 0: off)", Range{0, 20});
  v("delta_r", c.delta_r, "delta_r: ICP loss threshold (Eq. 2 sum) [m]", Above{0});
  v("acceptance", c.acceptance, "verification test", OneOf{"normalized", "loss"});
  v("max_mean_residual", c.max_mean_residual, "[m] normalized test: max mean inlier residual", Above{0});
  v("min_inlier_fraction", c.min_inlier_fraction, "normalized test: min inlier fraction", Range{0, 1});
  v("inlier_distance", c.inlier_distance, "[m] inlier residual bound", Above{0});
  v("min_translation_eigenvalue", c.min_translation_eigenvalue, "degeneracy: min translation eigenvalue of H/N", Range{0, 1});
  v("max_runner_up_ratio", c.max_runner_up_ratio, "uniqueness: max inliers of a distinct fit / best", Range{0, kInf});
  v("exclude_recent_distance", c.exclude_recent_distance, "[m] recent travel excluded from the search", AtLeast{0});
  v("submap_half_width", c.submap_half_width, "keyframes each side of a candidate in its submap", AtLeast{0});
  v("search_interval_after_loop", c.search_interval_after_loop, "[m] travel before searching again after a loop", AtLeast{0});
  v("seed", c.seed, "seed of the N_candi random draw", Any{});
  v("sgpr_model", c.sgpr_model, "SGPR weights (.sgw)", Any{});
}

template <class Visitor>
void visit_fields(SscConfig& c, Visitor&& v) {
  v("rings", c.rings, "rings between inner_radius and outer_radius", Range{1, 1000});
  v("sectors", c.sectors, "sectors of the descriptor", Range{1, 3600});
  v("inner_radius", c.inner_radius, "[m] range where the descriptor starts", AtLeast{0});
  v("outer_radius", c.outer_radius, "[m] range where the descriptor ends", Above{0});
  v("key_sectors", c.key_sectors, "sectors of the key-point projection (alignment)", Range{4, 3600});
  v("icp_iterations", c.icp_iterations, "max iterations of the alignment's 2D ICP (0 = yaw only)", Range{0, 1000});
  v("icp_window", c.icp_window, "[sectors] correspondence search either side", Range{0, 1800});
  v("icp_gate", c.icp_gate, "[m] max x or y offset of a correspondence", Above{0});
  v("max_translation", c.max_translation, "[m] larger x or y alignment falls back to 0", AtLeast{0});
  v("cell_size", c.cell_size, "[m] x-y cell thinning the stored points", Range{0.05, 5});
}

template <class Visitor>
void visit_fields(SlamConfig& c, Visitor&& v) {
  v("keyframe_distance", c.keyframe_distance, "[m] travel between keyframes", AtLeast{0});
  v("keyframe_angle_deg", c.keyframe_angle_deg, "[deg] rotation between keyframes", AtLeast{0});
  v("information_scale", c.information_scale, "[1/m^2] edge information = scale * H / N", Above{0});
  v("loop_robust_scale", c.loop_robust_scale, "Cauchy scale of loop edges", Above{0});
  v("max_iterations", c.max_iterations, "pose-graph iterations per optimisation", AtLeast{1});
  v("map_voxel_size", c.map_voxel_size, "[m] global map voxel size", Above{0});
  v("map_frame_step", c.map_frame_step, "every n-th frame goes into the global map", AtLeast{1});
}

template <class Visitor>
void visit_fields(SegmentationConfig& c, Visitor&& v) {
  v("model", c.model, "segmentation model description (.yaml; empty: the shipped one)", Any{});
  v("workers", c.workers, "scans segmented at once (one thread each)", Range{1, 64});
  v("lookahead", c.lookahead, "scans segmented ahead of the odometry", Range{1, 256});
}

template <class Visitor>
void visit_fields(LocalizeConfig& c, Visitor&& v) {
  v("relocalize_interval", c.relocalize_interval, "[m] travel between relocalisation attempts", AtLeast{0});
  v("confirmations", c.confirmations, "agreeing tracking fixes that confirm a relocalisation", Range{0, 100});
  v("confirm_interval", c.confirm_interval, "[m] travel between confirming fixes", AtLeast{0});
  v("max_runner_up_ratio", c.max_runner_up_ratio,
    "no prior: max inliers of a distinct fit / the candidate's (.inf: off)", Range{0, kInf});
  v("lateral_query_offset", c.lateral_query_offset,
    "[m] place recognition also from this far to either side (another lane; 0: off)", Range{0, 20});
  v("track_radius", c.track_radius, "[m] map keyframes this near the pose form the tracking submap", Above{0});
  v("submap_spacing", c.submap_spacing, "[m] least spacing of the tracking submap's keyframes", AtLeast{0});
  v("submap_rebuild_distance", c.submap_rebuild_distance, "[m] motion that rebuilds the tracking submap", Above{0});
  v("track_every", c.track_every, "register every n-th frame against the map", Range{1, 1000});
  v("track_min_inlier_fraction", c.track_min_inlier_fraction, "tracking fit: min inlier fraction", Range{0, 1});
  v("track_max_correction", c.track_max_correction, "[m] tracking fit: max correction of the prediction", Above{0});
  v("track_max_correction_deg", c.track_max_correction_deg, "[deg] tracking fit: max rotation correction", Above{0});
  v("leave_after", c.leave_after, "[m] travel without a fit that means leaving the map", Above{0});
  v("max_odometry_distance", c.max_odometry_distance, "[m] odometry-only travel after which frames are not placed", AtLeast{0});
  v("cached_keyframes", c.cached_keyframes, "map keyframes whose features stay in memory", Range{1, 10000000});
}

/// Calls v(section, struct) for every section; nested sections use dots.
template <class Visitor>
void visit_sections(SaloamConfig& c, Visitor&& v) {
  v("odometry", c.odometry);
  v("odometry.features", c.odometry.features);
  v("odometry.gravity", c.odometry.gravity);
  v("loop", c.loop);
  v("loop.ssc", c.loop.ssc);
  v("slam", c.slam);
  v("segmentation", c.segmentation);
  v("localize", c.localize);
}

/// Throws ConfigError, starting with `origin`, for the first field outside
/// its declared range (NaN never passes) or the first contradicting pair:
/// odometry.features.min_range < max_range, loop.delta_min <= delta_max,
/// odometry.features.pose_time_in_sweep <= sweep_duration,
/// odometry.gravity.mount_rpy_deg has 3 values or none,
/// loop.ssc.inner_radius < outer_radius.
void validate_config(const SaloamConfig& config, std::string_view origin = "configuration");
/// A configuration file may have at most this many bytes (config/saloam.yaml,
/// every key with its comment: about 20 KB).
inline constexpr std::size_t kMaxConfigBytes = std::size_t{1} << 20;
/// Loads a YAML file over the defaults. Unknown keys, wrong types and
/// invalid values (validate_config) are errors naming the file and the key;
/// a file that is not a regular file of at most kMaxConfigBytes (a FIFO,
/// /dev/zero) is an InputError, never waited on or read without end.
SaloamConfig load_config(const std::filesystem::path& path);
/// Applies YAML text over `config` (used by load_config; `origin` names the
/// source in errors). The result must pass validate_config; on any error
/// `config` is left unchanged.
void apply_config_yaml(SaloamConfig& config, std::string_view yaml_text, std::string_view origin);
/// Applies one "key=value" override, e.g. "odometry.alpha=0.2" or
/// "odometry.class_weight.pole=2". A bare Table I name ("alpha") works when
/// unique. The result must pass validate_config (so a pair is changed in the
/// order that keeps it consistent); on any error `config` is left unchanged.
void apply_config_override(SaloamConfig& config, std::string_view assignment);
/// Applies several overrides together (a command line's --set options): each
/// value is range-checked as it is set, the cross-field rules once at the
/// end, so their order does not matter.
void apply_config_overrides(SaloamConfig& config, const std::vector<std::string>& assignments);
/// Sets `key` to `value` for a command-line option bound to it (e.g. bench's
/// --threads to odometry.threads): the same checks as --set, errors naming
/// "OPTION VALUE". One validation for every way a value comes in.
void apply_config_option(SaloamConfig& config, std::string_view option, std::string_view key, std::string_view value);
/// The full configuration as commented YAML (every key, its value, meaning and range).
std::string config_to_yaml(const SaloamConfig& config);

}  // namespace saloam
