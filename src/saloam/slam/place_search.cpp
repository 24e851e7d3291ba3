#include "saloam/slam/place_search.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "saloam/core/lie.hpp"

namespace saloam {

namespace {
// Keyframes whose Scan Context is scored exactly per query, picked by their
// ring keys (as Scan Context's own retrieval).
constexpr std::size_t kRingKeyCandidates = 100;

// The kRingKeyCandidates candidates with the nearest ring keys, ascending.
std::vector<std::size_t> nearest_ring_keys(const KeyframeSet& set, const PlaceDescriptor& query,
                                           const std::vector<std::size_t>& candidates) {
  std::vector<std::pair<float, std::size_t>> by_key;
  by_key.reserve(candidates.size());
  for (const std::size_t k : candidates)
    by_key.emplace_back((set.place(k).context.ring_key - query.context.ring_key).squaredNorm(), k);
  std::partial_sort(by_key.begin(), by_key.begin() + static_cast<std::ptrdiff_t>(kRingKeyCandidates), by_key.end());
  std::vector<std::size_t> nearest;
  for (std::size_t i = 0; i < kRingKeyCandidates; ++i) nearest.push_back(by_key[i].second);
  std::sort(nearest.begin(), nearest.end());
  return nearest;
}

// The first `count` of `ranked` (best first), skipping a keyframe already
// taken (proposed by another query) and any within `distance` of one
// already taken (distance 0: only the same keyframe skipped).
std::vector<PlaceProposal> one_per_place(const KeyframeSet& set, const std::vector<PlaceProposal>& ranked,
                                         std::size_t count, double distance) {
  std::vector<PlaceProposal> chosen;
  for (const PlaceProposal& p : ranked) {
    if (chosen.size() >= count) break;
    const Eigen::Vector3d position = set.pose(p.keyframe).translation();
    const bool same_place = std::any_of(chosen.begin(), chosen.end(), [&](const PlaceProposal& other) {
      return other.keyframe == p.keyframe ||
             (distance > 0 && (set.pose(other.keyframe).translation() - position).norm() < distance);
    });
    if (!same_place) chosen.push_back(p);
  }
  return chosen;
}
}  // namespace

Eigen::Vector3d keyframe_up(const KeyframeSet& set, std::size_t k) {
  return set.level(k).transpose() * Eigen::Vector3d::UnitZ();
}

Eigen::Vector3d set_up(const KeyframeSet& set, std::size_t k) { return set.pose(k).linear() * keyframe_up(set, k); }

Pose sensor_frame_guess(const Pose& level_guess, const Eigen::Matrix3d& match_level, const Eigen::Matrix3d& query_level) {
  return orthonormalized(Pose(match_level.transpose()) * level_guess * Pose(query_level));
}

LoopVerificationSettings with_up(LoopVerificationSettings settings, const Eigen::Vector3d& up) {
  settings.coarse.up = settings.fine.up = up.normalized();
  return settings;
}

Pose PlaceProposal::lateral_guess() const {
  Pose query_from_sensor = Pose::Identity();
  query_from_sensor.translation().y() = -query_offset;
  return orthonormalized(place_match_guess(match) * query_from_sensor);
}

PlaceSearchOptions PlaceSearchOptions::from_config(const SaloamConfig& config, PlaceDetector detector,
                                                   double same_place_distance) {
  PlaceSearchOptions options;
  switch (detector) {
    case PlaceDetector::kSgpr: options.threshold = config.loop.zeta; break;
    case PlaceDetector::kSsc: options.threshold = config.loop.ssc_zeta; break;
    default: options.threshold = config.loop.scancontext_zeta; break;
  }
  options.count = static_cast<std::size_t>(std::max(0, config.loop.num_loop));
  options.same_place_distance = same_place_distance;
  return options;
}

std::vector<std::size_t> all_keyframes(const KeyframeSet& set) {
  std::vector<std::size_t> all(set.size());
  for (std::size_t k = 0; k < all.size(); ++k) all[k] = k;
  return all;
}

std::vector<std::size_t> thinned_near(const KeyframeSet& set, const Eigen::Vector3d& position, double radius,
                                      double spacing) {
  std::vector<std::size_t> kept;
  for (const std::size_t k : set.near(position, radius)) {
    if (!set.in_frame(k)) continue;
    const Eigen::Vector3d p = set.pose(k).translation();
    const bool crowded = std::any_of(kept.begin(), kept.end(), [&](std::size_t j) {
      return (set.pose(j).translation() - p).norm() < spacing;
    });
    if (!crowded) kept.push_back(k);
  }
  return kept;
}

ScoredCandidates score_candidates(const KeyframeSet& set, const PlaceRecognizer& places, const PlaceDescriptor& query,
                                  std::vector<std::size_t> candidates) {
  std::erase_if(candidates, [&](std::size_t k) { return !set.in_frame(k); });
  if (uses_scan_context(places.detector()) && candidates.size() > kRingKeyCandidates) {
    candidates = nearest_ring_keys(set, query, candidates);
  }
  std::vector<const PlaceDescriptor*> descriptors;
  descriptors.reserve(candidates.size());
  for (const std::size_t k : candidates) descriptors.push_back(&set.place(k));
  ScoredCandidates scored;
  scored.matches = places.match(query, descriptors);
  scored.keyframes = std::move(candidates);
  return scored;
}

std::vector<PlaceProposal> rank_places(const KeyframeSet& set, const ScoredCandidates& scored,
                                       const PlaceSearchOptions& options, double query_offset) {
  std::vector<PlaceProposal> above;
  for (std::size_t i = 0; i < scored.keyframes.size(); ++i) {
    if (scored.matches[i].score > options.threshold) above.push_back({scored.keyframes[i], scored.matches[i], query_offset});
  }
  std::sort(above.begin(), above.end(), [](const PlaceProposal& a, const PlaceProposal& b) {
    return a.match.score != b.match.score ? a.match.score > b.match.score : a.keyframe < b.keyframe;
  });
  return one_per_place(set, above, options.count, options.same_place_distance);
}

std::vector<PlaceProposal> merge_proposals(const KeyframeSet& set, std::vector<PlaceProposal> proposed,
                                           const PlaceSearchOptions& options) {
  std::stable_sort(proposed.begin(), proposed.end(), [](const PlaceProposal& a, const PlaceProposal& b) {
    return a.match.score > b.match.score;
  });
  return one_per_place(set, proposed, options.count, options.same_place_distance);
}

std::vector<PlaceProposal> propose_places(const KeyframeSet& set, const PlaceRecognizer& places,
                                          const std::vector<PlaceQuery>& queries,
                                          const std::vector<std::size_t>& candidates, const PlaceSearchOptions& options) {
  std::vector<PlaceProposal> proposed;
  for (const PlaceQuery& query : queries) {
    const ScoredCandidates scored = score_candidates(set, places, query.descriptor, candidates);
    const std::vector<PlaceProposal> ranked = rank_places(set, scored, options, query.offset);
    proposed.insert(proposed.end(), ranked.begin(), ranked.end());
  }
  return merge_proposals(set, std::move(proposed), options);
}

std::vector<PlaceQuery> sideways_queries(const PlaceRecognizer& places, const LabelledCloud& scan, double offset) {
  std::vector<PlaceQuery> queries;
  if (offset <= 0) return queries;
  for (const double y : {offset, -offset}) {
    LabelledCloud seen_from = scan;  // the points in a frame `y` to the left of the sensor
    for (Eigen::Vector3f& p : seen_from.points) p.y() -= static_cast<float>(y);
    queries.push_back({places.describe(seen_from), y});
  }
  return queries;
}

std::vector<PlaceQuery> lateral_queries(const PlaceRecognizer& places, const LabelledCloud& scan, double offset) {
  std::vector<PlaceQuery> queries{{places.describe(scan), 0.0}};
  for (PlaceQuery& query : sideways_queries(places, scan, offset)) queries.push_back(std::move(query));
  return queries;
}

void add_nearest(std::vector<PlaceProposal>& proposals, const KeyframeSet& set, const ScoredCandidates& scored,
                 const Eigen::Vector3d& position, double radius) {
  const std::vector<std::size_t>& candidates = scored.keyframes;
  std::size_t nearest = candidates.size();
  double best = radius * radius;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const double d2 = (set.pose(candidates[k]).translation() - position).squaredNorm();
    if (d2 < best) {
      best = d2;
      nearest = k;
    }
  }
  if (nearest == candidates.size()) return;
  const bool proposed = std::any_of(proposals.begin(), proposals.end(),
                                    [&](const PlaceProposal& p) { return p.keyframe == candidates[nearest]; });
  if (!proposed) proposals.push_back({candidates[nearest], scored.matches[nearest], 0.0, true});
}

LoopSubmap submap_around(const KeyframeSet& set, std::size_t match, std::size_t half_width,
                         const LoopVerificationSettings& settings, std::size_t end,
                         const std::function<bool(std::size_t)>& usable) {
  const Pose match_inverse = set.pose(match).inverse();
  const std::uint32_t session = set.session(match);
  LoopSubmap submap(settings);
  if (end == 0) return submap;
  const std::size_t first = match >= half_width ? match - half_width : 0;
  const std::size_t last = std::min(match + half_width, end - 1);
  for (std::size_t k = first; k <= last; ++k) {
    if (set.session(k) != session || (usable && !usable(k))) continue;
    submap.add(set.scan_features(k), match_inverse * set.pose(k));
  }
  return submap;
}

LoopVerificationSettings whole_map_verification(const SaloamConfig& config) {
  LoopVerificationSettings settings = LoopVerificationSettings::from_config(config);
  settings.max_runner_up_ratio = std::min(settings.max_runner_up_ratio, config.localize.max_runner_up_ratio);
  return settings;
}

bool small_correction(const Pose& predicted, const Pose& fitted, const LocalizeConfig& config) {
  const Pose difference = predicted.inverse() * fitted;
  return difference.translation().norm() <= config.track_max_correction &&
         rotation_angle(difference) <= config.track_max_correction_deg * M_PI / 180.0;
}

void require_measured_motion(LoopVerification& fit, const ScanFeatures& query, const LoopSubmap& submap,
                             const Pose& last_fix, const LoopVerificationSettings& settings) {
  if (!fit.accepted) return;
  const std::vector<Pose> guesses{last_fix};
  const LoopVerification again = verify_loop(query, submap, guesses, settings);
  if (again.registration.ok && same_fit(fit.relative, again.relative)) return;
  const Pose difference = fit.relative.inverse() * again.relative;
  fit.accepted = false;
  fit.reason = fmt::format("the fit follows the predicted motion: registered from the last fix it lands {:.1f} m, "
                           "{:.1f} deg elsewhere", difference.translation().norm(), rotation_angle(difference) * 180 / M_PI);
}

PlaceHypothesis PlaceHypothesis::from_fit(const Pose& pose, const Pose& odometry_pose, double travelled,
                                          int confirmations) {
  PlaceHypothesis h;
  h.set_from_odometry = orthonormalized(pose * odometry_pose.inverse());
  h.confirmations_left = confirmations;
  h.last_fix = travelled;
  h.last_pose = pose;
  return h;
}

Pose PlaceHypothesis::predict(const Pose& odometry_pose) const {
  return orthonormalized(set_from_odometry * odometry_pose);
}

bool PlaceHypothesis::confirm(const Pose& pose, const Pose& odometry_pose, double travelled) {
  set_from_odometry = orthonormalized(pose * odometry_pose.inverse());
  last_fix = travelled;
  last_pose = pose;
  return --confirmations_left <= 0;
}

}  // namespace saloam
