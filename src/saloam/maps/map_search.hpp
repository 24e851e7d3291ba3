#pragma once
// Searching a saved map for a place, shared by localisation (localizer.hpp)
// and the joining of sessions (session_join.hpp): the map keyframes whose
// place descriptors score best against a query, the verification submap
// around one of them, and the map keyframes near a position.

#include <algorithm>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/config.hpp"
#include "saloam/maps/prior_map.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/slam/loop_verification.hpp"

namespace saloam {

/// [m] map keyframes nearer than this to each other are one place: a search
/// proposes at most one of them.
inline constexpr double kSamePlaceDistance = 5.0;

/// A map keyframe proposed for verification and its descriptor's score.
struct PlaceCandidate {
  std::size_t keyframe = 0;
  PlaceMatch match;
};

/// The first `count` of `ranked` (best first; `keyframe_of(item)` its map
/// keyframe), skipping any within kSamePlaceDistance of one already taken.
template <class Item, class KeyframeOf>
std::vector<Item> one_per_place(const PriorMap& map, const std::vector<Item>& ranked, std::size_t count,
                                KeyframeOf keyframe_of) {
  std::vector<Item> chosen;
  for (const Item& item : ranked) {
    if (chosen.size() >= count) break;
    const Eigen::Vector3d position = map.pose(keyframe_of(item)).translation();
    const bool same_place = std::any_of(chosen.begin(), chosen.end(), [&](const Item& other) {
      return (map.pose(keyframe_of(other)).translation() - position).norm() < kSamePlaceDistance;
    });
    if (!same_place) chosen.push_back(item);
  }
  return chosen;
}

/// Verification of a place found with no prior (a search of the whole map,
/// by localisation or by the joining of sessions): the loop verification's
/// settings (LoopVerificationSettings::from_config) with the uniqueness test
/// of localize.max_runner_up_ratio, the stricter of the two ratios. Along a
/// street that the map cannot tell from another, a distinct fit nearly as
/// good as the candidate's exists, and with no prior nothing else tells
/// the two apart.
LoopVerificationSettings whole_map_verification(const SaloamConfig& config);

/// The detector's score threshold (loop.zeta, loop.ssc_zeta or
/// loop.scancontext_zeta).
double place_score_threshold(const SaloamConfig& config, PlaceDetector detector);

/// Among `candidates` (map keyframes), those whose descriptor scores above
/// `threshold` against `query`, best first (ties: the lower index), at most
/// `count`, and at most one within kSamePlaceDistance of another
/// (neighbouring keyframes are the same place). With a Scan Context detector only the 100 candidates
/// with the nearest ring keys (rotation invariant) are scored exactly, as
/// Scan Context's own retrieval does.
std::vector<PlaceCandidate> best_places(const PriorMap& map, const PlaceRecognizer& places,
                                        const PlaceDescriptor& query, std::vector<std::size_t> candidates,
                                        double threshold, std::size_t count);

/// The verification submap of map keyframe `match`: the keyframes up to
/// `half_width` either side of it in the same session, in match's sensor frame.
LoopSubmap submap_around(const PriorMap& map, std::size_t match, std::size_t half_width,
                         const LoopVerificationSettings& settings);

/// Whether the map itself measures the motion the odometry claims since the
/// last fix of a hypothesis: `query` registered against `submap` from
/// `last_fix` (the pose of the last fix, without the odometry's motion since;
/// in the submap's frame) must land within 0.5 m and 2 degrees of where
/// `fit` (its verification from the prediction) landed. A fit that follows
/// the prediction because the map constrains nothing along the street (a
/// hypothesis turned the wrong way along it slides with the wrongly
/// predicted motion) stays near `last_fix` instead: then `fit` is marked not
/// accepted, with the reason. Nothing is done when `fit` was not accepted.
void require_measured_motion(LoopVerification& fit, const ScanFeatures& query, const LoopSubmap& submap,
                             const Pose& last_fix, const LoopVerificationSettings& settings);

/// Map keyframes within `radius` of `position`, ascending, thinned so that
/// none lies within `spacing` of one kept before it.
std::vector<std::size_t> thinned_near(const PriorMap& map, const Eigen::Vector3d& position, double radius,
                                      double spacing);

}  // namespace saloam
