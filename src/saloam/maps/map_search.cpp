#include "saloam/maps/map_search.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "saloam/core/lie.hpp"

namespace saloam {

namespace {
// Map keyframes whose Scan Context is scored exactly per query, picked by
// their ring keys (as Scan Context's own retrieval).
constexpr std::size_t kRingKeyCandidates = 100;

// The kRingKeyCandidates candidates with the nearest ring keys, ascending.
std::vector<std::size_t> nearest_ring_keys(const PriorMap& map, const PlaceDescriptor& query,
                                           const std::vector<std::size_t>& candidates) {
  std::vector<std::pair<float, std::size_t>> by_key;
  by_key.reserve(candidates.size());
  for (const std::size_t k : candidates)
    by_key.emplace_back((map.place(k).context.ring_key - query.context.ring_key).squaredNorm(), k);
  std::partial_sort(by_key.begin(), by_key.begin() + static_cast<std::ptrdiff_t>(kRingKeyCandidates), by_key.end());
  std::vector<std::size_t> nearest;
  for (std::size_t i = 0; i < kRingKeyCandidates; ++i) nearest.push_back(by_key[i].second);
  std::sort(nearest.begin(), nearest.end());
  return nearest;
}
// Poses of keyframes of a session not linked to the first are in a frame of
// their own: never proposed in the map frame.
bool in_map_frame(const PriorMap& map, std::size_t k) {
  const SavedMap& saved = map.saved();
  const std::uint32_t session = saved.keyframes[k].session;
  return session >= saved.manifest.sessions.size() || saved.manifest.sessions[session].linked;
}
}  // namespace

LoopVerificationSettings whole_map_verification(const SaloamConfig& config) {
  LoopVerificationSettings settings = LoopVerificationSettings::from_config(config);
  settings.max_runner_up_ratio = std::min(settings.max_runner_up_ratio, config.localize.max_runner_up_ratio);
  return settings;
}

double place_score_threshold(const SaloamConfig& config, PlaceDetector detector) {
  switch (detector) {
    case PlaceDetector::kSgpr: return config.loop.zeta;
    case PlaceDetector::kSsc: return config.loop.ssc_zeta;
    default: return config.loop.scancontext_zeta;
  }
}

std::vector<PlaceCandidate> best_places(const PriorMap& map, const PlaceRecognizer& places,
                                        const PlaceDescriptor& query, std::vector<std::size_t> candidates,
                                        double threshold, std::size_t count) {
  std::erase_if(candidates, [&](std::size_t k) { return !in_map_frame(map, k); });
  if (uses_scan_context(places.detector()) && candidates.size() > kRingKeyCandidates) {
    candidates = nearest_ring_keys(map, query, candidates);
  }
  std::vector<const PlaceDescriptor*> descriptors;
  descriptors.reserve(candidates.size());
  for (const std::size_t k : candidates) descriptors.push_back(&map.place(k));
  const std::vector<PlaceMatch> scored = places.match(query, descriptors);
  std::vector<PlaceCandidate> above;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (scored[i].score > threshold) above.push_back({candidates[i], scored[i]});
  }
  std::sort(above.begin(), above.end(), [](const PlaceCandidate& a, const PlaceCandidate& b) {
    return a.match.score != b.match.score ? a.match.score > b.match.score : a.keyframe < b.keyframe;
  });
  return one_per_place(map, above, count, [](const PlaceCandidate& c) { return c.keyframe; });
}

LoopSubmap submap_around(const PriorMap& map, std::size_t match, std::size_t half_width,
                         const LoopVerificationSettings& settings) {
  const Pose match_inverse = map.pose(match).inverse();
  const std::uint32_t session = map.saved().keyframes[match].session;
  LoopSubmap submap(settings);
  const std::size_t first = match >= half_width ? match - half_width : 0;
  const std::size_t last = std::min(match + half_width, map.size() - 1);
  for (std::size_t k = first; k <= last; ++k) {
    if (map.saved().keyframes[k].session == session) submap.add(map.features(k)->expand(), match_inverse * map.pose(k));
  }
  return submap;
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

std::vector<std::size_t> thinned_near(const PriorMap& map, const Eigen::Vector3d& position, double radius,
                                      double spacing) {
  std::vector<std::size_t> kept;
  for (const std::size_t k : map.near(position, radius)) {
    if (!in_map_frame(map, k)) continue;
    const Eigen::Vector3d& p = map.pose(k).translation();
    const bool crowded = std::any_of(kept.begin(), kept.end(), [&](std::size_t j) {
      return (map.pose(j).translation() - p).norm() < spacing;
    });
    if (!crowded) kept.push_back(k);
  }
  return kept;
}

}  // namespace saloam
