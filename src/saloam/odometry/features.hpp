#pragma once
// LOAM feature extraction (paper Sec. III-B): on the rings of scan/rings.hpp,
// azimuth ordering, roughness (Eq. 1), rejection of unreliable points and the
// per-sector selection of edge and planar features. Each feature keeps its
// semantic class so that matching can stay within a class.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/config.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/core/types.hpp"
#include "saloam/scan/rings.hpp"

namespace saloam {

/// Compact class index used by the odometry: the SemanticKITTI training class
/// (0..19) of the point's static class. Index 0 holds every point of an
/// unlabeled scan or of a label-agnostic run.
using ClassIndex = std::uint8_t;
inline constexpr int kNumClassIndices = kNumLearningClasses;

/// Point sets of one scan, in the sensor frame at the instant the scan's pose
/// refers to (after de-skewing).
struct FeatureCloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<ClassIndex> classes;
  /// [s] for de-skewing: since the sweep start (the azimuth model), or the
  /// point's own time relative to the scan's timestamp when the scan has them.
  std::vector<float> sweep_time;

  [[nodiscard]] std::size_t size() const { return points.size(); }
  void push_back(const Eigen::Vector3d& p, ClassIndex c, float t) {
    points.push_back(p);
    classes.push_back(c);
    sweep_time.push_back(t);
  }
  void clear() {
    points.clear();
    classes.clear();
    sweep_time.clear();
  }
};

struct ScanFeatures {
  FeatureCloud edges;
  FeatureCloud planars;
};

/// Roughness of Eq. 1 for every point of one azimuth-ordered ring:
/// c_i = || sum_{j in S} (X_j - X_i) ||^2 over `half_window` neighbours on each
/// side, NOT normalised by |S| ||X_i||: this is the form of A-LOAM / F-LOAM,
/// for which the threshold alpha = 0.1 [m^2] of Table I is calibrated.
/// Points without a full window get +infinity.
std::vector<double> ring_roughness(const std::vector<Eigen::Vector3d>& ring, int half_window);

/// One flag per point of a ring (bytes: cheaper to read and copy than bits).
using PointMask = std::vector<std::uint8_t>;

/// Marks points whose roughness is not trustworthy (LOAM Sec. V-A): returns
/// too near or too far, occluded edges (a depth jump between ring neighbours:
/// the farther side is hidden behind the nearer one), surfaces hit at a
/// grazing angle (beam nearly parallel to the surface), and windows crossing
/// gaps in azimuth.
PointMask unreliable_points(const std::vector<Eigen::Vector3d>& ring, int half_window,
                                    double min_range, double max_range);

/// Selects features of one ring: split into N_r sectors; in each, up to N_e
/// points with roughness > alpha (sharpest first) become edges and up to N_p
/// with roughness < alpha (flattest first) planars; a selected point blocks
/// its ring neighbours (non-maximum suppression). Returns indices into ring.
struct RingSelection {
  std::vector<int> edges;
  std::vector<int> planars;
};
/// `not_edge` (empty or one flag per point) marks points that may only be planar.
RingSelection select_ring_features(const std::vector<Eigen::Vector3d>& ring,
                                   const std::vector<double>& roughness,
                                   const PointMask& unreliable, const FeatureConfig& config,
                                   const PointMask& not_edge = {});

/// Poles and tree trunks: objects whose cross-section is a small disc.
bool is_thin_round(std::uint16_t static_class_id);

/// One ring's crossing of a thin round object, reduced to its axis. The
/// crossing's returns lie on the side facing the sensor, and which of them
/// the roughness picks depends on the range (far: any; near: the
/// silhouette): a pole's or trunk's edge feature moves with the viewpoint,
/// and matched to map points seen from farther back it pulls each
/// registration back towards the previous pose (docs/odometry.md, "Scale
/// bias"). The axis does not move. The crossing is the run of ring
/// neighbours around the edge feature whose horizontal ranges change by less
/// than the largest radius from one to the next; the axis's azimuth halves
/// it; the radius is half its width (returns times azimuth step times the
/// axis's distance: the expected count of returns on a chord is its angular
/// width over the step); each return, at lateral offset s from the axis's
/// ray, lies sqrt(r^2 - s^2) in front of the axis (s is known to half a
/// step: the depth is averaged over that), and the axis's distance is the
/// mean of the returns' estimates, free of the selection bias of the nearest
/// return (the one with the most negative range noise).
struct ThinObjectAxis {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< on the axis, at the crossing's mean height
  int central = 0;      ///< ring index of the crossing's middle return
  double radius = 0.0;  ///< [m] estimated
};
/// The axis for the edge feature at ring index k of a ring in azimuth
/// order, or nothing when the crossing is wider than `max_radius` [m] (it
/// merges with another surface) or cut by something in front of it (a nearer
/// return next to either end).
std::optional<ThinObjectAxis> thin_object_axis(const std::vector<Eigen::Vector3d>& ring, int k, double max_radius);

/// The class index of a raw label for the odometry, or -1 when the point must
/// not be used (dynamic classes, unlabeled, outlier).
int odometry_class(std::uint16_t raw_label);

/// Matching group of a class index (SemanticKITTI training class): classes
/// that a segmentation network confuses with each other and that share a
/// geometry are merged, named by a representative class: ground (road,
/// parking, sidewalk, other-ground, terrain -> road), vertical structure
/// (building, fence -> building), pole-like (pole, trunk, traffic-sign ->
/// pole), vehicles (car, bicycle, motorcycle, truck, other-vehicle -> car).
/// Vegetation stays alone. Index 0 (unlabeled mode) stays 0.
ClassIndex class_group(ClassIndex c);

/// Full extraction on one scan, rings as scan_rings() finds them; each
/// feature's sweep time (for de-skewing) is the point's own time when the
/// cloud has per-point times (LabelledCloud::time, relative to the scan's
/// timestamp), else the sweep model's (sweep_time_from_azimuth). With `use_labels` false (unlabeled scan or
/// label-agnostic mode) every point is class 0; otherwise dynamic and
/// unlabeled points are dropped from the features (after the roughness, which
/// is pure geometry: removing them first would create false edges).
/// With `parallel`, rings are processed as TBB tasks (same result).
/// `up` (sensor frame, odometry/gravity.hpp) is what heights are measured
/// along: the ground below which no edges are taken, a pole's axis.
ScanFeatures extract_features(const LabelledCloud& cloud, const FeatureConfig& config, bool use_labels,
                              bool parallel = false, const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

/// The cloud with every point mapped by T (classes and sweep times kept).
FeatureCloud transformed(const FeatureCloud& cloud, const Pose& T);

}  // namespace saloam
