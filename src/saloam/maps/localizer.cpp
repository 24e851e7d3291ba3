#include "saloam/maps/localizer.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/lie.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/slam/loop_candidates.hpp"

namespace saloam {


std::string_view localization_status_name(LocalizationStatus status) {
  switch (status) {
    case LocalizationStatus::kUnplaced: return "unplaced";
    case LocalizationStatus::kLocalized: return "localized";
    case LocalizationStatus::kOdometry: return "odometry";
  }
  return "?";
}

/// The map keyframes near a place, in the map frame, at both radii of the verification.
struct Localizer::Submap {
  explicit Submap(const LoopVerificationSettings& settings) : features(settings) {}
  LoopSubmap features;
  Eigen::Vector3d built_at = Eigen::Vector3d::Zero();
  std::vector<std::size_t> keyframes;
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< in the map frame, as its first keyframe sees it
};

Localizer::Localizer(const SaloamConfig& config, const PriorMap& map, std::optional<SgprNetwork> network)
    : config_(config),
      map_(map),
      odometry_(config.odometry),
      places_(PlaceRecognizer::from_config(config.loop, std::move(network))),
      verification_(LoopVerificationSettings::from_config(config)),
      unique_verification_(whole_map_verification(config)),
      tracking_(RegistrationSettings::from_config(config.odometry)) {
  tracking_.parallel = false;
  tracking_.inlier_distance = config.loop.inlier_distance;
  tracking_.level_line_max_rise = 0;  // as the verification's fits (LoopVerificationSettings)
  search_ = PlaceSearchOptions::from_config(config, places_.detector(), kSamePlaceDistance);
}

Localizer::~Localizer() = default;

const LocalizedFrame& Localizer::process(const LabelledCloud& scan, double timestamp) {
  LocalizedFrame out;
  out.frame = frames_.size();
  out.timestamp = timestamp;
  const StageTimer timer;
  const std::size_t previous = odometry_.poses().size();
  out.odometry_pose = odometry_.register_frame(scan, timestamp);
  out.timing.odometry_ms = timer.elapsed_ms();
  if (previous > 0) travelled_ += (odometry_.poses()[previous - 1].translation() - out.odometry_pose.translation()).norm();

  const LocalizeConfig& lc = config_.localize;
  if (state_ == State::kTracking) {
    track(out);
  } else {
    if (hypothesis_) {
      confirm(out);
    } else if (state_ == State::kOdometry) {
      reenter(out);
    }
    // Still not placed in the map: try place recognition.
    // (Not before the third frame: the first scans are not de-skewed yet.)
    if (state_ != State::kTracking && !hypothesis_ && odometry_.poses().size() >= 3 &&
        travelled_ - last_relocalization_ >= lc.relocalize_interval) {
      relocalize(scan, out);
    }
  }
  if (state_ == State::kOdometry && travelled_ - last_fix_ > lc.max_odometry_distance) {
    spdlog::warn("frame {}: {:.0f} m on the odometry alone since the last fix in the map: frames are no longer placed "
                 "until the run relocalises", out.frame, travelled_ - last_fix_);
    out.event = out.event.empty() ? "odometry fallback exhausted" : out.event;
    state_ = State::kLost;
  }

  switch (state_) {
    case State::kLost: out.status = LocalizationStatus::kUnplaced; break;
    case State::kTracking: out.status = LocalizationStatus::kLocalized; break;
    case State::kOdometry: out.status = LocalizationStatus::kOdometry; break;
  }
  if (out.status != LocalizationStatus::kUnplaced) {
    out.pose = orthonormalized(map_from_odometry_ * out.odometry_pose);
    out.since_fix = travelled_ - last_fix_;
  }
  frames_.push_back(std::move(out));
  return frames_.back();
}

const Localizer::Submap& Localizer::submap_near(const Eigen::Vector3d& position) {
  const LocalizeConfig& lc = config_.localize;
  if (submap_ && (submap_->built_at - position).norm() <= lc.submap_rebuild_distance) return *submap_;
  auto submap = std::make_unique<Submap>(verification_);
  submap->built_at = position;
  // Keyframes near the place, thinned to submap_spacing (the map's overlap a lot).
  submap->keyframes = thinned_near(map_, position, lc.track_radius, lc.submap_spacing);
  for (const std::size_t k : submap->keyframes) submap->features.add(map_.features(k)->expand(), map_.pose(k));
  if (!submap->keyframes.empty()) submap->up = set_up(map_, submap->keyframes.front());
  submap_ = std::move(submap);
  return *submap_;
}

LoopVerification Localizer::verify_near(const Pose& predicted) {
  const Submap& submap = submap_near(predicted.translation());
  LoopVerification v;
  if (submap.keyframes.empty()) {
    v.reason = "no map keyframe near";
    return v;
  }
  const std::vector<Pose> guesses{predicted};
  return verify_loop(odometry_.last_features(), submap.features, guesses, with_up(verification_, submap.up));
}

void Localizer::track(LocalizedFrame& out) {
  const LocalizeConfig& lc = config_.localize;
  const StageTimer timer;
  ++frames_since_track_;
  if (frames_since_track_ >= static_cast<std::size_t>(lc.track_every)) {
    frames_since_track_ = 0;
    const Pose predicted = orthonormalized(map_from_odometry_ * out.odometry_pose);
    const Submap& submap = submap_near(predicted.translation());
    out.submap_keyframes = submap.keyframes.size();
    if (!submap.keyframes.empty()) {
      const ScanFeatures& features = odometry_.last_features();
      RegistrationSettings tracking = tracking_;
      tracking.up = submap.up;
      const RegistrationResult fit =
          register_scan(features.edges, features.planars, submap.features.fine(), predicted, tracking);
      const double total = static_cast<double>(features.edges.size() + features.planars.size());
      out.inlier_fraction = total > 0 ? fit.inliers / total : 0.0;
      out.mean_residual = fit.mean_inlier_residual();
      if (fit.ok && out.inlier_fraction >= lc.track_min_inlier_fraction && small_correction(predicted, fit.pose, lc)) {
        map_from_odometry_ = orthonormalized(fit.pose * out.odometry_pose.inverse());
        last_fix_ = travelled_;
        out.fitted = true;
      }
    }
  }
  if (travelled_ - last_fix_ > lc.leave_after) {
    const Eigen::Vector3d p = (map_from_odometry_ * out.odometry_pose).translation();
    spdlog::info("frame {}: left the mapped area at ({:.1f}, {:.1f}) in the map ({:.0f} m without a fit): going on "
                 "with the odometry alone", out.frame, p.x(), p.y(), travelled_ - last_fix_);
    out.event = "left the mapped area";
    state_ = State::kOdometry;
    last_reentry_try_ = travelled_;
  }
  out.timing.tracking_ms += timer.elapsed_ms();
}

void Localizer::reenter(LocalizedFrame& out) {
  const LocalizeConfig& lc = config_.localize;
  if (travelled_ - last_reentry_try_ < lc.confirm_interval) return;
  const Pose predicted = orthonormalized(map_from_odometry_ * out.odometry_pose);
  if (map_.near(predicted.translation(), 0.5 * lc.track_radius).empty()) return;  // still outside
  last_reentry_try_ = travelled_;
  const StageTimer timer;
  const LoopVerification v = verify_near(predicted);
  out.inlier_fraction = v.inlier_fraction;
  out.mean_residual = v.mean_residual;
  out.submap_keyframes = submap_ ? submap_->keyframes.size() : 0;
  if (v.accepted) {
    map_from_odometry_ = orthonormalized(v.relative * out.odometry_pose.inverse());
    last_fix_ = travelled_;
    out.fitted = true;
    state_ = State::kTracking;
    frames_since_track_ = 0;
    out.event = "re-entered the mapped area";
    spdlog::info("frame {}: back in the mapped area (correction {:.2f} m)", out.frame,
                 (predicted.inverse() * v.relative).translation().norm());
  }
  out.timing.tracking_ms += timer.elapsed_ms();
}

void Localizer::confirm(LocalizedFrame& out) {
  const LocalizeConfig& lc = config_.localize;
  PlaceHypothesis& h = *hypothesis_;
  if (travelled_ - h.last_fix < lc.confirm_interval) return;
  const StageTimer timer;
  const Pose predicted = h.predict(out.odometry_pose);
  RelocalizationRecord record;
  record.frame = out.frame;
  record.travelled = travelled_;
  record.verification = verify_near(predicted);
  record.pose = record.verification.relative;
  out.inlier_fraction = record.verification.inlier_fraction;
  out.mean_residual = record.verification.mean_residual;
  if (record.verification.accepted && small_correction(predicted, record.verification.relative, lc)) {
    require_measured_motion(record.verification, odometry_.last_features(), submap_->features, h.last_pose,
                            with_up(verification_, submap_->up));
  }
  const bool agrees = record.verification.accepted && small_correction(predicted, record.verification.relative, lc);
  if (!agrees) {
    record.outcome = "refuted";
    hypothesis_.reset();
  } else if (h.confirm(record.verification.relative, out.odometry_pose, travelled_)) {
    record.outcome = "confirmed";
    out.event = state_ == State::kOdometry ? "relocalised (was on the odometry)" : "relocalised";
    spdlog::info("frame {}: relocalised in the map at ({:.1f}, {:.1f}) after {:.1f} m", out.frame,
                 record.pose.translation().x(), record.pose.translation().y(), travelled_);
    place(h, out);
  } else {
    record.outcome = "confirms";
  }
  relocalizations_.push_back(std::move(record));
  out.timing.relocalization_ms += timer.elapsed_ms();
}

void Localizer::place(const PlaceHypothesis& h, LocalizedFrame& out) {
  map_from_odometry_ = h.set_from_odometry;
  last_fix_ = travelled_;
  if (!first_placed_) first_placed_ = travelled_;
  state_ = State::kTracking;
  frames_since_track_ = 0;
  out.fitted = true;
  hypothesis_.reset();
}

std::vector<std::size_t> Localizer::relocalization_candidates(const LocalizedFrame& out) const {
  // On the odometry (left the map not long ago) a place must lie within
  // Eq. 3's radius of where the odometry says the run is, as a loop
  // candidate must: the drift since the last fix is bounded. Only a run
  // that was never placed, or whose odometry fallback ran out, searches the
  // whole map.
  if (state_ != State::kOdometry) return all_keyframes(map_);
  const Eigen::Vector3d predicted = (map_from_odometry_ * out.odometry_pose).translation();
  return map_.near(predicted, search_radius(CandidateGate::from_config(config_.loop), travelled_ - last_fix_));
}

void Localizer::relocalize(const LabelledCloud& scan, LocalizedFrame& out) {
  last_relocalization_ = travelled_;
  const StageTimer timer;
  // The scan described level (as the map's keyframes were), from the
  // sensor and a lane width to either side.
  const Eigen::Vector3d up = out.odometry_pose.linear().transpose() * odometry_.up();
  const Eigen::Matrix3d level = points_up(up) ? Eigen::Matrix3d::Identity() : level_rotation(up);
  const double offset = config_.localize.lateral_query_offset;
  const std::vector<PlaceQuery> queries =
      level.isIdentity() ? lateral_queries(places_, scan, offset) : lateral_queries(places_, turned(scan, level), offset);
  const std::vector<PlaceProposal> chosen = propose_places(map_, places_, queries, relocalization_candidates(out), search_);
  const std::size_t w = static_cast<std::size_t>(std::max(0, config_.loop.submap_half_width));
  // With no prior (the whole map searched) the fit must also be unique.
  const LoopVerificationSettings& settings = state_ == State::kOdometry ? verification_ : unique_verification_;
  for (const PlaceProposal& proposal : chosen) {
    const std::size_t match = proposal.keyframe;
    const LoopSubmap submap = submap_around(map_, match, w, verification_, map_.size());
    // Guesses: the descriptor's (its yaw, SSC's offset, the query's side); on the odometry also where it says we are.
    std::vector<Pose> guesses{sensor_frame_guess(proposal.lateral_guess(), map_.level(match), level)};
    if (state_ == State::kOdometry) {
      add_distinct_guess(guesses, orthonormalized(map_.pose(match).inverse() * map_from_odometry_ * out.odometry_pose));
    }
    RelocalizationRecord record;
    record.frame = out.frame;
    record.travelled = travelled_;
    record.keyframe = match;
    record.score = proposal.match;
    record.verification = verify_loop(odometry_.last_features(), submap, guesses, with_up(settings, keyframe_up(map_, match)));
    record.pose = orthonormalized(map_.pose(match) * record.verification.relative);
    const bool accepted = record.verification.accepted;
    if (accepted) {
      const PlaceHypothesis h =
          PlaceHypothesis::from_fit(record.pose, out.odometry_pose, travelled_, config_.localize.confirmations);
      if (h.confirmed()) {
        record.outcome = "confirmed";
        out.event = "relocalised";
        place(h, out);
      } else {
        record.outcome = "hypothesis";
        hypothesis_ = h;
      }
    } else {
      record.outcome = "rejected";
    }
    relocalizations_.push_back(std::move(record));
    if (accepted) break;
  }
  out.timing.relocalization_ms += timer.elapsed_ms();
}

}  // namespace saloam
