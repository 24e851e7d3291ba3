#pragma once
// Semantic Scan Context (Li, Kong, Zhao, Li, Liu, "SSC: Semantic Scan Context
// for Large-Scale Place Recognition", IROS 2021; arXiv 2107.00382).
//
// A training-free semantic polar descriptor with a global alignment (the
// paper's method section; the steps below are named as there):
//  - Semantic preprocessing: the SemanticKITTI classes are
//    reduced to the 11 static background classes of the paper's priority
//    order (terrain < road < parking < sidewalk < other-ground < vegetation <
//    building < fence < trunk < pole < traffic-sign); vehicles, people and
//    unlabelled points are dropped.
//  - Two-step global semantic ICP: key points are the
//    nearest point of the key classes (building, fence, trunk, pole,
//    traffic-sign) in each azimuth sector of the x-y plane. Step 1: the yaw
//    is the circular shift minimising the L1 distance between the two
//    scans' key ranges (refined below one sector by a parabola through the
//    minimum and its neighbours). Step 2: an ICP on the 2D key points,
//    correspondences searched within a few sectors of the shifted one and
//    gated in x and y, estimates x and y (and refines the yaw).
//  - Descriptor: rings x sectors between an inner and an
//    outer radius, each cell holding the highest-priority class of its
//    points (0 = empty). The candidate's descriptor is rebuilt after its
//    points are moved by the alignment.
//  - Similarity: among the cells occupied in either
//    descriptor, the fraction whose classes are equal.
//
// Beyond the paper's code: each sector's key point is the nearest one (the
// public code keeps the last point read), the yaw is refined below one
// sector, and the ICP estimates the yaw with x and y. The points stored per
// scan are thinned to one per x-y cell (loop.ssc.cell_size) so that a
// descriptor can be rebuilt after alignment without keeping the whole scan.
//
// Frames and units: points in the sensor frame (x forward, y left, z up),
// metres; angles in radians, counter-clockwise about z. An alignment is
// T_query<-candidate: a candidate point p lands at R(yaw) p + t in the query.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"

namespace saloam {

/// The class code of a raw SemanticKITTI id in the paper's priority order:
/// 1 terrain, 2 road (and lane-marking), 3 parking, 4 sidewalk, 5
/// other-ground, 6 vegetation, 7 building, 8 fence, 9 trunk, 10 pole, 11
/// traffic-sign; 0 for every other class (ignored).
std::uint8_t ssc_class_code(std::uint16_t raw_id);
/// Codes of the key classes the alignment uses (building and above).
inline constexpr std::uint8_t kSscFirstKeyCode = 7;
inline constexpr std::uint8_t kSscNumCodes = 12;  ///< codes 0..11

/// What is kept of one scan.
struct SemanticScanContext {
  /// Thinned points (x, y in the sensor frame) and their class codes (1..11).
  std::vector<Eigen::Vector2f> points;
  std::vector<std::uint8_t> codes;
  /// The scan's own descriptor, rings x sectors, row-major by ring: codes (0 = empty).
  std::vector<std::uint8_t> cells;
  /// Per key sector: x-y range of the nearest key point (0 = none) and its position.
  std::vector<float> key_range;
  std::vector<Eigen::Vector2f> key_points;

  [[nodiscard]] std::size_t bytes() const;
};

/// Builds the descriptor of a labelled scan (points in the sensor frame).
/// Without labels every point is ignored and the descriptor is empty.
SemanticScanContext make_semantic_scan_context(const LabelledCloud& scan, const SscConfig& config = {});

/// Rigid motion in the x-y plane, T_query<-candidate.
struct SscAlignment {
  double yaw = 0;                                       ///< [rad] in (-pi, pi]
  Eigen::Vector2d translation = Eigen::Vector2d::Zero();  ///< [m]
  int correspondences = 0;  ///< key-point pairs of the last ICP iteration
  int iterations = 0;       ///< ICP iterations run
  bool translation_capped = false;  ///< the ICP's translation exceeded max_translation and was reset to 0
};

/// The two-step global semantic ICP: the candidate's key points onto the query's.
SscAlignment align_semantic_scan_contexts(const SemanticScanContext& query, const SemanticScanContext& candidate,
                                          const SscConfig& config = {});

/// The descriptor (codes per cell, as in SemanticScanContext::cells) of
/// thinned points moved by `alignment`.
std::vector<std::uint8_t> ssc_cells(const std::vector<Eigen::Vector2f>& points, const std::vector<std::uint8_t>& codes,
                                    const SscAlignment& alignment, const SscConfig& config = {});

/// Fraction of the cells occupied in either descriptor whose codes are
/// equal, in [0, 1] (0 when none is occupied).
double ssc_similarity(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b);

struct SscMatch {
  double score = 0;        ///< ssc_similarity after the alignment
  SscAlignment alignment;  ///< T_query<-candidate
};

/// Aligns the candidate to the query and scores the aligned descriptors.
SscMatch match_semantic_scan_contexts(const SemanticScanContext& query, const SemanticScanContext& candidate,
                                      const SscConfig& config = {});

}  // namespace saloam
