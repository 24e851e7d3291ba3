#pragma once
// The one place search: "where among these keyframes is this scan?", asked
// by the live SLAM (loop closure, paper Sec. III-C), by localisation in a
// saved map and by the joining of sessions, answered one way:
//
//   gate     the candidates: earlier keyframes within Eq. 3's radius of the
//            estimate (loop_candidates.hpp), the keyframes near a prediction
//            (KeyframeSet::near, Eq. 3's radius or a tracking radius), or the
//            whole set; keyframes whose session is not in the set's frame
//            are never proposed
//   score    each candidate's descriptor against the query's (the detector's
//            score; with Scan Context only the 100 nearest ring keys exactly,
//            as Scan Context's own retrieval)
//   rank     above the detector's threshold (loop.zeta, ssc_zeta,
//            scancontext_zeta), best first (ties: the older keyframe), at
//            most N_loop (loop.num_loop), at most one per place
//   verify   the query's features registered against the submap of the
//            keyframes around a proposal (loop_verification.hpp)
//
// The three callers differ only in where their candidates come from and in
// what an accepted fit becomes: a loop edge of the pose graph (SlamSystem),
// or a PlaceHypothesis that later fixes near its prediction must confirm
// (Localizer, the joining of sessions).
//
// Frames: a set's poses are T_set<-sensor at the keyframes' pose instants,
// the set's frame being its first keyframe's; a submap is in the proposed
// keyframe's sensor frame, a guess is T_keyframe<-query sensor.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/odometry/features.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/slam/loop_verification.hpp"

namespace saloam {

/// Keyframes a place is searched among: the live SLAM's (SlamSystem) or a
/// saved map's (PriorMap).
class KeyframeSet {
 public:
  virtual ~KeyframeSet() = default;
  [[nodiscard]] virtual std::size_t size() const = 0;
  /// T_set<-sensor of keyframe k, the current estimate.
  [[nodiscard]] virtual Pose pose(std::size_t k) const = 0;
  /// The drive keyframe k belongs to.
  [[nodiscard]] virtual std::uint32_t session(std::size_t k) const = 0;
  /// Whether keyframe k's pose is in the set's frame (its session linked to
  /// the first); the others are never proposed.
  [[nodiscard]] virtual bool in_frame(std::size_t k) const = 0;
  [[nodiscard]] virtual const PlaceDescriptor& place(std::size_t k) const = 0;
  /// The rotation that turned keyframe k's scan level (odometry/gravity.hpp)
  /// before place(k) described it: R * up_k = z, up_k = R^T z in its sensor frame.
  [[nodiscard]] virtual Eigen::Matrix3d level(std::size_t k) const = 0;
  /// Keyframe k's odometry features in its sensor frame (a saved map reads
  /// them on demand).
  [[nodiscard]] virtual ScanFeatures scan_features(std::size_t k) const = 0;
  /// Keyframes whose position lies within `radius` [m] of `position`, ascending.
  [[nodiscard]] virtual std::vector<std::size_t> near(const Eigen::Vector3d& position, double radius) const = 0;

 protected:
  KeyframeSet() = default;
  KeyframeSet(const KeyframeSet&) = default;
  KeyframeSet(KeyframeSet&&) = default;
  KeyframeSet& operator=(const KeyframeSet&) = default;
  KeyframeSet& operator=(KeyframeSet&&) = default;
};

/// Up in keyframe k's sensor frame (level(k)^T z).
Eigen::Vector3d keyframe_up(const KeyframeSet& set, std::size_t k);
/// Up in the set's frame, as keyframe k sees it.
Eigen::Vector3d set_up(const KeyframeSet& set, std::size_t k);
/// A guess between two level frames (a descriptor's: yaw about up, SSC's
/// offset, a query from the side), T_match_level<-query_level, turned into
/// T_match<-query between the sensor frames.
Pose sensor_frame_guess(const Pose& level_guess, const Eigen::Matrix3d& match_level, const Eigen::Matrix3d& query_level);
/// `settings` with up in the frame of keyframe `match` of `set` (a submap
/// around it is in its frame).
LoopVerificationSettings with_up(LoopVerificationSettings settings, const Eigen::Vector3d& up);

/// A keyframe proposed for verification: the one proposal type of the three callers.
struct PlaceProposal {
  std::size_t keyframe = 0;
  PlaceMatch match;           ///< the descriptors' score (and yaw, SSC's offset)
  double query_offset = 0;    ///< [m] the query was described this far to the sensor's left (0: from the sensor)
  bool by_proximity = false;  ///< proposed for its estimated distance, not its score
  /// T_keyframe<-sensor that the query gives: the match's guess
  /// (place_match_guess) composed with the query's side, orthonormalised.
  [[nodiscard]] Pose lateral_guess() const;
};

/// A query: a place descriptor and the side it was described from.
struct PlaceQuery {
  PlaceDescriptor descriptor;
  double offset = 0;  ///< [m] to the sensor's left
};

/// [m] keyframes of a saved map nearer than this to each other are one
/// place: a search of a map proposes at most one of them.
inline constexpr double kSamePlaceDistance = 5.0;

struct PlaceSearchOptions {
  double threshold = 0;            ///< the detector's score threshold
  std::size_t count = 0;           ///< N_loop: proposals at most
  double same_place_distance = 0;  ///< [m] proposals nearer than this are one place (0: each keyframe its own)

  /// The threshold of `detector` (loop.zeta, loop.ssc_zeta or
  /// loop.scancontext_zeta) and loop.num_loop.
  static PlaceSearchOptions from_config(const SaloamConfig& config, PlaceDetector detector, double same_place_distance);
};

/// The candidates that were scored and their matches, index by index.
struct ScoredCandidates {
  std::vector<std::size_t> keyframes;
  std::vector<PlaceMatch> matches;
};

/// The whole set as candidates: every keyframe, ascending.
std::vector<std::size_t> all_keyframes(const KeyframeSet& set);

/// Keyframes within `radius` of `position` (in the set's frame), ascending,
/// thinned so that none lies within `spacing` of one kept before it.
std::vector<std::size_t> thinned_near(const KeyframeSet& set, const Eigen::Vector3d& position, double radius,
                                      double spacing);

/// Scores `query` against `candidates` (those in the set's frame; with a
/// Scan Context detector and more than 100 of them, the 100 with the nearest
/// ring keys).
ScoredCandidates score_candidates(const KeyframeSet& set, const PlaceRecognizer& places, const PlaceDescriptor& query,
                                  std::vector<std::size_t> candidates);

/// Those of `scored` above the threshold, best first (ties: the lower
/// index), at most `count`, one per place; `query_offset` marks them.
std::vector<PlaceProposal> rank_places(const KeyframeSet& set, const ScoredCandidates& scored,
                                       const PlaceSearchOptions& options, double query_offset = 0);

/// The proposals of several queries (each from rank_places, in query
/// order) as one: the best `count` (stable: the earlier query first among
/// equal scores), one per place; a keyframe proposed by two queries keeps
/// its best proposal.
std::vector<PlaceProposal> merge_proposals(const KeyframeSet& set, std::vector<PlaceProposal> proposed,
                                           const PlaceSearchOptions& options);

/// Each query scored and ranked, then merged (merge_proposals).
std::vector<PlaceProposal> propose_places(const KeyframeSet& set, const PlaceRecognizer& places,
                                          const std::vector<PlaceQuery>& queries,
                                          const std::vector<std::size_t>& candidates, const PlaceSearchOptions& options);

/// The scan described from `offset` metres to its left and to its right
/// (another lane: Scan Context compares scans taken from one spot); none
/// when `offset` is 0.
std::vector<PlaceQuery> sideways_queries(const PlaceRecognizer& places, const LabelledCloud& scan, double offset);

/// The scan described from the sensor, then its sideways_queries.
std::vector<PlaceQuery> lateral_queries(const PlaceRecognizer& places, const LabelledCloud& scan, double offset);

/// Beyond the paper: the scored candidate nearest to `position` (set frame),
/// when nearer than `radius`, is proposed too whatever its score (marked
/// by_proximity) unless already proposed.
void add_nearest(std::vector<PlaceProposal>& proposals, const KeyframeSet& set, const ScoredCandidates& scored,
                 const Eigen::Vector3d& position, double radius);

/// The verification submap of keyframe `match`: the keyframes up to
/// `half_width` either side of it, before `end`, of its session, that
/// `usable` admits (all when empty), in match's sensor frame.
LoopSubmap submap_around(const KeyframeSet& set, std::size_t match, std::size_t half_width,
                         const LoopVerificationSettings& settings, std::size_t end,
                         const std::function<bool(std::size_t)>& usable = {});

/// Verification of a place found with no prior (a search of the whole map):
/// the loop verification's settings with the uniqueness test of
/// localize.max_runner_up_ratio, the stricter of the two ratios. Along a
/// street that the map cannot tell from another, a distinct fit nearly as
/// good as the candidate's exists, and with no prior nothing else tells the
/// two apart.
LoopVerificationSettings whole_map_verification(const SaloamConfig& config);

/// Whether a fit lands within localize.track_max_correction (m, deg) of its prediction.
bool small_correction(const Pose& predicted, const Pose& fitted, const LocalizeConfig& config);

/// Whether the set itself measures the motion the odometry claims since the
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

/// A place found but not yet trusted (localisation, the joining of
/// sessions): the link T_set<-odometry that a verified fit gives, and the
/// later fixes near its prediction it still needs (localize.confirmations,
/// localize.confirm_interval metres apart).
struct PlaceHypothesis {
  Pose set_from_odometry = Pose::Identity();  ///< T_set<-odometry frame
  int confirmations_left = 0;
  double last_fix = 0;                        ///< [m] path length at the last fix
  Pose last_pose = Pose::Identity();          ///< T_set<-sensor at the last fix

  /// The hypothesis of a fit that puts the sensor at `pose` (T_set<-sensor)
  /// where the odometry put it at `odometry_pose`, `travelled` metres along.
  static PlaceHypothesis from_fit(const Pose& pose, const Pose& odometry_pose, double travelled, int confirmations);
  /// T_set<-sensor it predicts for `odometry_pose`.
  [[nodiscard]] Pose predict(const Pose& odometry_pose) const;
  /// A fix that agrees (at `pose`, `travelled` metres along): the link moves
  /// to it; true when that was the last confirmation needed.
  bool confirm(const Pose& pose, const Pose& odometry_pose, double travelled);
  [[nodiscard]] bool confirmed() const { return confirmations_left <= 0; }
};

}  // namespace saloam
