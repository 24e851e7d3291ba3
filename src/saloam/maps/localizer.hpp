#pragma once
// Localisation in a saved map (`saloam localize`, docs/map_format.md). Per
// frame the semantic odometry registers the scan as in any run; on top:
//
//  * Not placed (the start, or after the odometry fallback ran out):
//    every localize.relocalize_interval metres the scan is described (from
//    the sensor and from a lane width to either side: Scan Context compares
//    scans taken from one spot) and scored against every map keyframe (the
//    map's detector; the place search, slam/place_search.hpp), the best
//    loop.num_loop above the detector's threshold are verified exactly as
//    loop closure verifies a candidate (semantic ICP against the keyframes
//    around it, coarse to fine, from the descriptor's yaw; the normalized
//    acceptance test). An accepted fit is a hypothesis, not yet a pose.
//    With no prior at all (the run's start, or after the odometry fallback
//    ran out; the whole map is searched) the fit must also be unique along
//    its least constrained direction (localize.max_runner_up_ratio): a
//    street the map cannot tell from another is not a place.
//  * Hypothesis: localize.confirmations later fixes, confirm_interval metres
//    apart, must agree: each registers the scan against the map around the
//    pose the odometry predicts from the hypothesis and must pass the same
//    acceptance test with a small correction; registered again from the
//    last fix's pose (without the odometry's motion since), it must land
//    on the same pose: the map, not the prediction, fixes it. Then the run is placed
//    ("relocalised"); a fix that fails refutes the hypothesis. Frames before
//    the confirmation are not placed (no pose is guessed).
//  * Tracking: every localize.track_every-th frame registers against the
//    map keyframes near the predicted pose (T_map<-odom * odometry pose); a
//    fit with enough inliers and a small correction updates T_map<-odom; the
//    odometry carries the frames between. After localize.leave_after metres
//    without a usable fit (or with no map keyframe near) the run has left
//    the mapped area: it says so and goes on with the odometry alone
//    (status "odometry").
//  * Odometry: fits against the map near the predicted pose (re-entry, the
//    acceptance test of loop closure) and global relocalisation attempts
//    continue; either places the run again. Beyond
//    localize.max_odometry_distance metres without a fix, frames are no
//    longer placed.
//
// Poses are T_map<-sensor at the scan's pose instant, map frame = the saved
// map's. Everything runs on the caller's thread (the odometry may use more).

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/maps/prior_map.hpp"
#include "saloam/odometry/semantic_odometry.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/slam/loop_verification.hpp"
#include "saloam/slam/place_search.hpp"

namespace saloam {

/// What a frame's pose is worth.
enum class LocalizationStatus {
  kUnplaced,   ///< no pose: not (yet) relocalised, or odometry fallback exhausted
  kLocalized,  ///< in the map: tracked against it (this frame or a few metres before)
  kOdometry,   ///< outside the mapped area: the odometry since the last fix
};
std::string_view localization_status_name(LocalizationStatus status);

struct LocalizeFrameTimings {
  double odometry_ms = 0;
  double relocalization_ms = 0;  ///< descriptor, scoring, verification of candidates
  double tracking_ms = 0;        ///< submap and registration against the map
  [[nodiscard]] double total_ms() const { return odometry_ms + relocalization_ms + tracking_ms; }
};

struct LocalizedFrame {
  std::size_t frame = 0;
  double timestamp = 0;
  LocalizationStatus status = LocalizationStatus::kUnplaced;
  Pose pose = Pose::Identity();     ///< T_map<-sensor (meaningless when unplaced)
  Pose odometry_pose = Pose::Identity();
  bool fitted = false;              ///< registered against the map at this frame (fit used)
  double since_fix = 0;             ///< [m] travelled since the last fit used (0 when fitted)
  double inlier_fraction = -1;      ///< of this frame's fit against the map (-1: none tried)
  double mean_residual = -1;        ///< [m]
  std::size_t submap_keyframes = 0; ///< map keyframes in the tracking submap
  std::string event;                ///< "relocalised", "left the mapped area", ... (empty: none)
  LocalizeFrameTimings timing;
};

/// One verified relocalisation candidate or confirming fix.
struct RelocalizationRecord {
  std::size_t frame = 0;
  double travelled = 0;                   ///< [m] since the run's start
  std::optional<std::size_t> keyframe;    ///< map keyframe (candidates; none for confirming fixes)
  PlaceMatch score;
  LoopVerification verification;
  Pose pose = Pose::Identity();           ///< T_map<-sensor this fit gives
  std::string outcome;                    ///< "rejected", "hypothesis", "confirms", "confirmed", "refuted"
};

class Localizer {
 public:
  /// `network`: the SGPR weights when the map's detector uses SGPR.
  Localizer(const SaloamConfig& config, const PriorMap& map, std::optional<SgprNetwork> network);
  ~Localizer();
  Localizer(const Localizer&) = delete;
  Localizer& operator=(const Localizer&) = delete;

  /// Processes the next scan.
  const LocalizedFrame& process(const LabelledCloud& scan, double timestamp);

  [[nodiscard]] const std::vector<LocalizedFrame>& frames() const { return frames_; }
  [[nodiscard]] const std::vector<RelocalizationRecord>& relocalizations() const { return relocalizations_; }
  [[nodiscard]] const SemanticOdometry& odometry() const { return odometry_; }
  [[nodiscard]] double travelled() const { return travelled_; }
  /// [m] travelled when the run was first placed (none: never).
  [[nodiscard]] std::optional<double> first_placed_at() const { return first_placed_; }

 private:
  enum class State { kLost, kTracking, kOdometry };
  struct Submap;

  void relocalize(const LabelledCloud& scan, LocalizedFrame& out);
  /// The map keyframes a relocalisation attempt scores: all of them, or on
  /// the odometry those within Eq. 3's radius of the prediction.
  [[nodiscard]] std::vector<std::size_t> relocalization_candidates(const LocalizedFrame& out) const;
  void confirm(LocalizedFrame& out);
  /// A confirmed hypothesis places the run: tracking from this frame on.
  void place(const PlaceHypothesis& h, LocalizedFrame& out);
  void track(LocalizedFrame& out);
  void reenter(LocalizedFrame& out);
  /// The tracking submap around `position` (rebuilt when it moved far enough).
  const Submap& submap_near(const Eigen::Vector3d& position);
  /// Registration against the tracking submap from `predicted`, with the loop acceptance test.
  LoopVerification verify_near(const Pose& predicted);

  SaloamConfig config_;
  const PriorMap& map_;
  SemanticOdometry odometry_;
  PlaceRecognizer places_;
  LoopVerificationSettings verification_;
  LoopVerificationSettings unique_verification_;  ///< whole_map_verification: a place found with no prior
  RegistrationSettings tracking_;
  PlaceSearchOptions search_;  ///< loop.num_loop, one per kSamePlaceDistance

  State state_ = State::kLost;
  std::optional<PlaceHypothesis> hypothesis_;  ///< T_map<-odometry to confirm
  Pose map_from_odometry_ = Pose::Identity();
  double travelled_ = 0;
  double last_fix_ = 0;              ///< travelled at the last fit used
  double last_relocalization_ = -1e300;
  double last_reentry_try_ = -1e300;
  std::size_t frames_since_track_ = 0;
  std::optional<double> first_placed_;
  std::unique_ptr<Submap> submap_;

  std::vector<LocalizedFrame> frames_;
  std::vector<RelocalizationRecord> relocalizations_;
};

}  // namespace saloam
