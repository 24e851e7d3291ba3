#include "saloam/maps/localizer.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/lie.hpp"
#include "saloam/core/profiling.hpp"

namespace saloam {

namespace {
// Guesses closer than this to the first one converge to the same fit.
constexpr double kSameGuessTranslation = 1.0;            // [m]
constexpr double kSameGuessRotation = 5.0 * M_PI / 180;  // [rad]
// Map keyframes whose Scan Context is scored exactly per relocalisation
// attempt, picked by their ring keys (as Scan Context's own retrieval).
constexpr std::size_t kRingKeyCandidates = 100;
}  // namespace

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
};

Localizer::Localizer(const SaloamConfig& config, const PriorMap& map, std::optional<SgprNetwork> network)
    : config_(config),
      map_(map),
      odometry_(config.odometry),
      places_(parse_place_detector(config.loop.detector), std::move(network), GraphBuilderConfig{}, ScanContextConfig{},
              config.loop.ssc),
      verification_(LoopVerificationSettings::from_config(config)),
      tracking_(RegistrationSettings::from_config(config.odometry)) {
  tracking_.parallel = false;
  tracking_.inlier_distance = config.loop.inlier_distance;
  tracking_.level_line_max_rise = 0;  // as the verification's fits (LoopVerificationSettings)
  switch (places_.detector()) {
    case PlaceDetector::kSgpr: score_threshold_ = config.loop.zeta; break;
    case PlaceDetector::kSsc: score_threshold_ = config.loop.ssc_zeta; break;
    default: score_threshold_ = config.loop.scancontext_zeta; break;
  }
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
  for (const std::size_t k : map_.near(position, lc.track_radius)) {
    const Eigen::Vector3d& p = map_.pose(k).translation();
    const bool crowded = std::any_of(submap->keyframes.begin(), submap->keyframes.end(), [&](std::size_t j) {
      return (map_.pose(j).translation() - p).norm() < lc.submap_spacing;
    });
    if (!crowded) submap->keyframes.push_back(k);
  }
  for (const std::size_t k : submap->keyframes) submap->features.add(map_.features(k)->expand(), map_.pose(k));
  submap_ = std::move(submap);
  return *submap_;
}

bool Localizer::small_correction(const Pose& predicted, const Pose& fitted) const {
  const Pose difference = predicted.inverse() * fitted;
  return difference.translation().norm() <= config_.localize.track_max_correction &&
         rotation_angle(difference) <= config_.localize.track_max_correction_deg * M_PI / 180.0;
}

LoopVerification Localizer::verify_near(const Pose& predicted) {
  const Submap& submap = submap_near(predicted.translation());
  LoopVerification v;
  if (submap.keyframes.empty()) {
    v.reason = "no map keyframe near";
    return v;
  }
  const std::vector<Pose> guesses{predicted};
  return verify_loop(odometry_.last_features(), submap.features, guesses, verification_);
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
      const RegistrationResult fit =
          register_scan(features.edges, features.planars, submap.features.fine(), predicted, tracking_);
      const double total = static_cast<double>(features.edges.size() + features.planars.size());
      out.inlier_fraction = total > 0 ? fit.inliers / total : 0.0;
      out.mean_residual = fit.mean_inlier_residual();
      if (fit.ok && out.inlier_fraction >= lc.track_min_inlier_fraction && small_correction(predicted, fit.pose)) {
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
  Hypothesis& h = *hypothesis_;
  if (travelled_ - h.last_fix < lc.confirm_interval) return;
  const StageTimer timer;
  const Pose predicted = orthonormalized(h.map_from_odometry * out.odometry_pose);
  RelocalizationRecord record;
  record.frame = out.frame;
  record.travelled = travelled_;
  record.verification = verify_near(predicted);
  record.pose = record.verification.relative;
  out.inlier_fraction = record.verification.inlier_fraction;
  out.mean_residual = record.verification.mean_residual;
  const bool agrees = record.verification.accepted && small_correction(predicted, record.verification.relative);
  if (agrees) {
    h.map_from_odometry = orthonormalized(record.verification.relative * out.odometry_pose.inverse());
    h.last_fix = travelled_;
    if (--h.confirmations_left <= 0) {
      record.outcome = "confirmed";
      map_from_odometry_ = h.map_from_odometry;
      last_fix_ = travelled_;
      if (!first_placed_) first_placed_ = travelled_;
      out.event = state_ == State::kOdometry ? "relocalised (was on the odometry)" : "relocalised";
      spdlog::info("frame {}: relocalised in the map at ({:.1f}, {:.1f}) after {:.1f} m", out.frame,
                   record.pose.translation().x(), record.pose.translation().y(), travelled_);
      state_ = State::kTracking;
      frames_since_track_ = 0;
      out.fitted = true;
      hypothesis_.reset();
    } else {
      record.outcome = "confirms";
    }
  } else {
    record.outcome = "refuted";
    hypothesis_.reset();
  }
  relocalizations_.push_back(std::move(record));
  out.timing.relocalization_ms += timer.elapsed_ms();
}

void Localizer::relocalize(const LabelledCloud& scan, LocalizedFrame& out) {
  last_relocalization_ = travelled_;
  const StageTimer timer;
  const PlaceDescriptor query = places_.describe(scan);
  // On the odometry (left the map not long ago) a place must lie within
  // Eq. 3's radius of where the odometry says the run is, as a loop
  // candidate must: the drift since the last fix is bounded. Only a run
  // that was never placed, or whose odometry fallback ran out, searches the
  // whole map.
  std::vector<std::size_t> candidates;
  if (state_ == State::kOdometry) {
    const Eigen::Vector3d predicted = (map_from_odometry_ * out.odometry_pose).translation();
    const double radius =
        std::max(config_.loop.delta_min, std::min(config_.loop.delta_max, config_.loop.sigma * (travelled_ - last_fix_)));
    candidates = map_.near(predicted, radius);
  } else {
    candidates.resize(map_.size());
    for (std::size_t k = 0; k < map_.size(); ++k) candidates[k] = k;
  }
  // Scan Context's retrieval step on a large map: the nearest ring keys
  // (rotation invariant) first, the exact column-shift distance for those only.
  if (uses_scan_context(places_.detector()) && candidates.size() > kRingKeyCandidates) {
    std::vector<std::pair<float, std::size_t>> by_key;
    by_key.reserve(candidates.size());
    for (const std::size_t k : candidates)
      by_key.emplace_back((map_.place(k).context.ring_key - query.context.ring_key).squaredNorm(), k);
    std::partial_sort(by_key.begin(), by_key.begin() + static_cast<std::ptrdiff_t>(kRingKeyCandidates), by_key.end());
    candidates.clear();
    for (std::size_t i = 0; i < kRingKeyCandidates; ++i) candidates.push_back(by_key[i].second);
    std::sort(candidates.begin(), candidates.end());
  }
  std::vector<const PlaceDescriptor*> descriptors;
  descriptors.reserve(candidates.size());
  for (const std::size_t k : candidates) descriptors.push_back(&map_.place(k));
  const std::vector<PlaceMatch> scored = places_.match(query, descriptors);
  std::unordered_map<std::size_t, PlaceMatch> matches;
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (scored[i].score > score_threshold_) {
      order.push_back(candidates[i]);
      matches[candidates[i]] = scored[i];
    }
  }
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return matches[a].score != matches[b].score ? matches[a].score > matches[b].score : a < b;
  });
  const auto n = static_cast<std::size_t>(std::max(0, config_.loop.num_loop));
  // Neighbouring keyframes are the same place: verify at most one of each stretch.
  std::vector<std::size_t> chosen;
  for (const std::size_t k : order) {
    if (chosen.size() >= n) break;
    const bool same_place = std::any_of(chosen.begin(), chosen.end(), [&](std::size_t c) {
      return (map_.pose(c).translation() - map_.pose(k).translation()).norm() < 5.0;
    });
    if (!same_place) chosen.push_back(k);
  }
  const std::size_t w = static_cast<std::size_t>(std::max(0, config_.loop.submap_half_width));
  for (const std::size_t match : chosen) {
    const Pose match_inverse = map_.pose(match).inverse();
    LoopSubmap submap(verification_);
    const std::size_t first = match >= w ? match - w : 0, last = std::min(match + w, map_.size() - 1);
    for (std::size_t k = first; k <= last; ++k) submap.add(map_.features(k)->expand(), match_inverse * map_.pose(k));
    // Guesses: the descriptor's yaw (and SSC's offset); on the odometry also where it says we are.
    std::vector<Pose> guesses;
    Pose yaw_guess = Pose::Identity();
    if (matches[match].yaw) {
      yaw_guess.linear() = Eigen::AngleAxisd(*matches[match].yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      if (matches[match].translation) yaw_guess.translation().head<2>() = *matches[match].translation;
    }
    guesses.push_back(yaw_guess);
    if (state_ == State::kOdometry) {
      const Pose estimate = orthonormalized(match_inverse * map_from_odometry_ * out.odometry_pose);
      const Pose difference = yaw_guess.inverse() * estimate;
      if (difference.translation().norm() > kSameGuessTranslation || rotation_angle(difference) > kSameGuessRotation)
        guesses.push_back(estimate);
    }
    RelocalizationRecord record;
    record.frame = out.frame;
    record.travelled = travelled_;
    record.keyframe = match;
    record.score = matches[match];
    record.verification = verify_loop(odometry_.last_features(), submap, guesses, verification_);
    record.pose = orthonormalized(map_.pose(match) * record.verification.relative);
    const bool accepted = record.verification.accepted;
    if (accepted) {
      Hypothesis h;
      h.map_from_odometry = orthonormalized(record.pose * out.odometry_pose.inverse());
      h.confirmations_left = config_.localize.confirmations;
      h.last_fix = travelled_;
      if (h.confirmations_left <= 0) {
        record.outcome = "confirmed";
        map_from_odometry_ = h.map_from_odometry;
        last_fix_ = travelled_;
        if (!first_placed_) first_placed_ = travelled_;
        state_ = State::kTracking;
        frames_since_track_ = 0;
        out.fitted = true;
        out.event = "relocalised";
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
