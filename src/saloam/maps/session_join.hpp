#pragma once
// Joining the map of one drive to another's (`saloam slam SOURCE --map MAP
// --save-map MAP2` and `saloam merge MAP_A MAP_B --out MAP`,
// docs/map_format.md): cross-session loop closure and one pose graph.
//
// The base map keeps its frame (its first keyframe, held fixed). The joining
// map's keyframes are gone through in order, as a run would meet them:
//
//  * Not linked: every localize.relocalize_interval metres of its path (not
//    from its first two frames, which are not de-skewed) the keyframe's place descriptor is scored against every base keyframe; the
//    best loop.num_loop above the detector's threshold are verified as loop
//    closure verifies a candidate (semantic ICP against the keyframes
//    loop.submap_half_width either side, from the descriptor's yaw; the loop
//    acceptance test). Found with no prior, the fit must also be unique
//    along its least constrained direction (localize.max_runner_up_ratio,
//    place_search.hpp's whole_map_verification), as in localisation. An
//    accepted fit is a hypothesis of T_base<-joining.
//  * Hypothesis: as localisation confirms a relocalisation (localizer.hpp),
//    localize.confirmations later keyframes, localize.confirm_interval
//    metres apart, must register against the base keyframes near the pose
//    the hypothesis predicts (the acceptance test, a correction below
//    localize.track_max_correction, and registered again from the last
//    fix's pose the same pose: place_search.hpp's require_measured_motion);
//    a failing one refutes it. Confirmed,
//    the hypothesis and its confirmations become cross-session loop edges and
//    the joining map is linked. Before that it is a component of its own.
//  * Linked: from then on each keyframe (after an accepted loop, once per
//    loop.search_interval_after_loop metres) searches the base keyframes
//    within Eq. 3's radius of where the link puts it (the path since the
//    last cross-session loop as d), scores and verifies them as loops; an
//    accepted one that moves the link no more than the joining map drifts
//    (localize.track_max_correction, growing with loop.sigma * d) is a
//    further edge and updates the link.
//
// Linked, one pose graph over both maps (both maps' edges and the
// cross-session ones) is optimised from the base poses and the joining
// poses carried by the link (slam.* options, base keyframe 0 fixed); the
// joining map's poses are then in the base frame. Not linked, both keep
// their poses and the joining sessions are marked not linked. Sessions of
// either map that were not linked in it stay as they are (never searched).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/maps/map_format.hpp"
#include "saloam/maps/prior_map.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/slam/loop_verification.hpp"
#include "saloam/slam/pose_graph.hpp"

namespace saloam {

/// One verified cross-session candidate or confirming fit.
struct CrossSessionRecord {
  std::size_t query = 0;      ///< keyframe of the joining map
  std::size_t match = 0;      ///< keyframe of the base map (a confirming fit: the one nearest the prediction)
  double travelled = 0;       ///< [m] along the joining map's path at the query
  PlaceMatch score;           ///< the descriptors' (zero for confirming fits)
  LoopVerification verification;
  Pose pose = Pose::Identity();  ///< T_base<-query the fit gives
  /// "rejected", "hypothesis", "confirms", "confirmed", "refuted" (before
  /// the link), "loop" / "rejected loop" (after it).
  std::string outcome;
};

struct JoinedMaps {
  /// The base map's keyframes, then the joining map's (their sessions
  /// numbered after the base's); edges of both and the cross-session ones.
  SavedMap map;
  std::size_t base_keyframes = 0;
  std::vector<CrossSessionRecord> records;
  std::optional<std::size_t> linked_at;  ///< joining keyframe whose fit confirmed the link (none: not linked)
  double linked_after = 0;               ///< [m] of the joining map's path at the link
  std::size_t cross_session_loops = 0;   ///< edges between the maps
  PoseGraphSummary optimization;         ///< of the joint graph (not run when not linked)
};

/// Joins `joining` to `base` (see above) with `config` (the base map's; the
/// detector must be both maps': InputError otherwise). `places` scores the
/// descriptors (its detector is config's).
JoinedMaps join_maps(const PriorMap& base, const PriorMap& joining, const SaloamConfig& config,
                     const PlaceRecognizer& places);

/// Writes the joined map into `folder` (write_map), reading each keyframe's
/// features from the map it came from.
void write_joined_map(const std::filesystem::path& folder, const JoinedMaps& joined, const PriorMap& base,
                      const PriorMap& joining);

}  // namespace saloam
