#pragma once
// Loop-candidate generation (paper Sec. III-C, Eq. 3): earlier keyframes
// whose current position estimate lies within
//     delta_d = max(delta_min, min(delta_max, sigma * d))
// of the query's, d being the distance travelled between the two. The radius
// grows with d because the odometry drifts by about sigma per metre; it is
// bounded below (place recognition works within a few metres anyway) and
// above (no search over the whole map). Frames travelled less than
// `exclude_recent_distance` ago are never candidates. When more than N_candi
// frames qualify, N_candi are drawn at random (seeded): with accumulated
// drift the nearest frames by the estimate are not the likeliest matches.

#include <cstddef>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/config.hpp"

namespace saloam {

/// Eq. 3's gate, built from the configuration (loop.*), which holds the
/// defaults; a default-constructed gate is all zeros.
struct CandidateGate {
  double sigma{};                    ///< drift rate [m per m travelled]
  double delta_min{};                ///< [m]
  double delta_max{};                ///< [m]
  double exclude_recent_distance{};  ///< [m]
  std::size_t max_candidates{};      ///< N_candi

  static CandidateGate from_config(const LoopClosureConfig& config);
};

/// delta_d of Eq. 3 for a travelled distance d [m].
double search_radius(const CandidateGate& gate, double travelled);

/// Where a keyframe is (current estimate, world frame) and how far the
/// vehicle had travelled when it was taken [m, along the odometry].
struct KeyframePlace {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double travelled = 0;
};

/// Indices into `earlier` of the candidates for `query`, ascending. Draws from
/// `rng` only when more than `max_candidates` qualify (a partial
/// Fisher-Yates shuffle on the raw 64-bit output, so the draw is the same on
/// every platform).
std::vector<std::size_t> loop_candidates(const KeyframePlace& query, std::span<const KeyframePlace> earlier,
                                         const CandidateGate& gate, std::mt19937_64& rng);

}  // namespace saloam
