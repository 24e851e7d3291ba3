#include "saloam/maps/session_join.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/slam/loop_candidates.hpp"
#include "saloam/slam/place_search.hpp"

namespace saloam {

namespace {

// The first scans of a run are not de-skewed (the odometry has no motion
// yet): as localisation, no place is searched for from them.
constexpr std::uint64_t kFirstDeskewedFrame = 2;
// Levenberg-Marquardt iterations per phase of the joint optimisation (at least).
constexpr int kJoinIterations = 100;

bool session_linked(const SavedMap& map, std::size_t k) {
  const std::uint32_t s = map.keyframes[k].session;
  return s >= map.manifest.sessions.size() || map.manifest.sessions[s].linked;
}

// A cross-session constraint: T_base_k<-joining_q as fitted.
struct CrossEdge {
  std::size_t base = 0, joining = 0;
  Pose measured = Pose::Identity();
  Matrix6d information = Matrix6d::Identity();
};

class SessionJoiner {
 public:
  SessionJoiner(const PriorMap& base, const PriorMap& joining, const SaloamConfig& config, const PlaceRecognizer& places)
      : base_(base), joining_(joining), config_(config), places_(places),
        verification_(LoopVerificationSettings::from_config(config)),
        whole_map_verification_(whole_map_verification(config)),
        gate_(CandidateGate::from_config(config.loop)),
        search_(PlaceSearchOptions::from_config(config, places.detector(), kSamePlaceDistance)) {}

  JoinedMaps run();

 private:
  void relocalize(std::size_t q);
  void confirm(std::size_t q);
  void search_loop(std::size_t q);
  /// Registers joining keyframe q against the base keyframes near `predicted`
  /// (T_base<-q); accepted only when the base map measures the motion since
  /// `last_fix` (T_base<-keyframe of the hypothesis' last fix; require_measured_motion).
  CrossSessionRecord fit_near(std::size_t q, const Pose& predicted, const Pose& last_fix) const;
  /// Registers joining keyframe q against the base keyframes around `candidate`.
  CrossSessionRecord verify(std::size_t q, const PlaceProposal& candidate, std::vector<Pose> guesses,
                            const LoopVerificationSettings& settings) const;
  [[nodiscard]] CrossEdge edge_of(const CrossSessionRecord& r) const {
    return {r.match, r.query, r.verification.relative,
            registration_information(r.verification.registration, 1.0, config_.slam.information_scale)};
  }
  /// A cross-session loop after the link may correct the link's prediction
  /// only as much as the joining map drifts: localize.track_max_correction
  /// (m, deg), times loop.sigma * `since` / track_max_correction where that
  /// is more (`since`: path since the last cross-session loop). Else `r` is
  /// marked not accepted: another place that looks alike.
  void require_link_agrees(CrossSessionRecord& r, const Pose& predicted, double since) const;
  /// The confirmed hypothesis links the maps; its fits become edges.
  void link(std::size_t q);
  JoinedMaps assemble() const;
  std::vector<Pose> optimize(JoinedMaps& out) const;

  const PriorMap& base_;
  const PriorMap& joining_;
  const SaloamConfig& config_;
  const PlaceRecognizer& places_;
  LoopVerificationSettings verification_;
  LoopVerificationSettings whole_map_verification_;  ///< a place found with no prior must be unique
  CandidateGate gate_;
  PlaceSearchOptions search_;  ///< loop.num_loop, one per kSamePlaceDistance

  std::vector<double> path_;  ///< [m] along the joining map's keyframes (sessions one after the other)
  std::optional<PlaceHypothesis> hypothesis_;  ///< T_base<-joining to confirm
  std::vector<CrossEdge> hypothesis_edges_;    ///< its fits so far
  std::optional<Pose> base_from_joining_;  ///< the link (updated by each cross-session loop)
  Pose initial_link_ = Pose::Identity();    ///< the link as confirmed: places the joining poses before the optimisation
  std::optional<std::size_t> linked_at_;
  double last_attempt_ = -1e300, last_loop_ = -1e300;
  std::vector<CrossEdge> edges_;
  std::vector<CrossSessionRecord> records_;
};

JoinedMaps SessionJoiner::run() {
  const SavedMap& j = joining_.saved();
  path_.assign(j.keyframes.size(), 0.0);
  for (std::size_t k = 1; k < j.keyframes.size(); ++k) {
    const bool same = j.keyframes[k].session == j.keyframes[k - 1].session;
    path_[k] = path_[k - 1] + (same ? j.keyframes[k].travelled - j.keyframes[k - 1].travelled : 0.0);
  }
  for (std::size_t q = 0; q < j.keyframes.size(); ++q) {
    if (!session_linked(j, q)) continue;
    if (base_from_joining_) {
      search_loop(q);
    } else if (hypothesis_) {
      confirm(q);
    } else if (j.keyframes[q].frame >= kFirstDeskewedFrame && path_[q] - last_attempt_ >= config_.localize.relocalize_interval) {
      relocalize(q);
    }
  }
  JoinedMaps out = assemble();
  if (linked_at_) {
    const std::vector<Pose> poses = optimize(out);
    for (std::size_t k = 0; k < poses.size(); ++k) out.map.keyframes[k].pose = poses[k];
  }
  return out;
}

CrossSessionRecord SessionJoiner::verify(std::size_t q, const PlaceProposal& candidate, std::vector<Pose> guesses,
                                         const LoopVerificationSettings& settings) const {
  const std::size_t w = static_cast<std::size_t>(std::max(0, config_.loop.submap_half_width));
  const LoopSubmap submap = submap_around(base_, candidate.keyframe, w, verification_, base_.size());
  add_distinct_guess(guesses, sensor_frame_guess(place_match_guess(candidate.match), base_.level(candidate.keyframe),
                                                joining_.level(q)));
  CrossSessionRecord r;
  r.query = q;
  r.match = candidate.keyframe;
  r.travelled = path_[q];
  r.score = candidate.match;
  r.verification =
      verify_loop(joining_.features(q)->expand(), submap, guesses, with_up(settings, keyframe_up(base_, candidate.keyframe)));
  r.pose = orthonormalized(base_.pose(candidate.keyframe) * r.verification.relative);
  return r;
}

void SessionJoiner::relocalize(std::size_t q) {
  last_attempt_ = path_[q];
  const std::vector<PlaceQuery> query{{joining_.place(q), 0.0}};
  for (const PlaceProposal& c : propose_places(base_, places_, query, all_keyframes(base_), search_)) {
    CrossSessionRecord r = verify(q, c, {}, whole_map_verification_);
    if (!r.verification.accepted) {
      r.outcome = "rejected";
      records_.push_back(std::move(r));
      continue;
    }
    hypothesis_ = PlaceHypothesis::from_fit(r.pose, joining_.pose(q), path_[q], config_.localize.confirmations);
    hypothesis_edges_ = {edge_of(r)};
    r.outcome = hypothesis_->confirmed() ? "confirmed" : "hypothesis";
    records_.push_back(std::move(r));
    if (hypothesis_->confirmed()) link(q);
    return;
  }
}

CrossSessionRecord SessionJoiner::fit_near(std::size_t q, const Pose& predicted, const Pose& last_fix) const {
  const LocalizeConfig& lc = config_.localize;
  CrossSessionRecord r;
  r.query = q;
  r.travelled = path_[q];
  const std::vector<std::size_t> near = thinned_near(base_, predicted.translation(), lc.track_radius, lc.submap_spacing);
  if (near.empty()) {
    r.verification.reason = "no base keyframe near";
    r.pose = predicted;
    return r;
  }
  r.match = *std::min_element(near.begin(), near.end(), [&](std::size_t a, std::size_t b) {
    return (base_.pose(a).translation() - predicted.translation()).norm() <
           (base_.pose(b).translation() - predicted.translation()).norm();
  });
  const Pose match_inverse = base_.pose(r.match).inverse();
  LoopSubmap submap(verification_);
  for (const std::size_t k : near) submap.add(base_.features(k)->expand(), match_inverse * base_.pose(k));
  const std::vector<Pose> guesses{orthonormalized(match_inverse * predicted)};
  const ScanFeatures query = joining_.features(q)->expand();
  const LoopVerificationSettings settings = with_up(verification_, keyframe_up(base_, r.match));
  r.verification = verify_loop(query, submap, guesses, settings);
  r.pose = orthonormalized(base_.pose(r.match) * r.verification.relative);
  require_measured_motion(r.verification, query, submap, match_inverse * last_fix, settings);
  return r;
}

void SessionJoiner::confirm(std::size_t q) {
  PlaceHypothesis& h = *hypothesis_;
  if (path_[q] - h.last_fix < config_.localize.confirm_interval) return;
  const Pose predicted = h.predict(joining_.pose(q));
  CrossSessionRecord r = fit_near(q, predicted, h.last_pose);
  if (!r.verification.accepted || !small_correction(predicted, r.pose, config_.localize)) {
    r.outcome = "refuted";
    records_.push_back(std::move(r));
    hypothesis_.reset();
    last_attempt_ = path_[q];
    return;
  }
  hypothesis_edges_.push_back(edge_of(r));
  const bool confirmed = h.confirm(r.pose, joining_.pose(q), path_[q]);
  r.outcome = confirmed ? "confirmed" : "confirms";
  records_.push_back(std::move(r));
  if (confirmed) link(q);
}

void SessionJoiner::link(std::size_t q) {
  base_from_joining_ = hypothesis_->set_from_odometry;
  initial_link_ = hypothesis_->set_from_odometry;
  linked_at_ = q;
  last_loop_ = path_[q];
  edges_.insert(edges_.end(), hypothesis_edges_.begin(), hypothesis_edges_.end());
  spdlog::info("joining keyframe {} ({:.1f} m along its path): linked to the base map by {} verified fits", q, path_[q],
               hypothesis_edges_.size());
  hypothesis_.reset();
  hypothesis_edges_.clear();
}

void SessionJoiner::require_link_agrees(CrossSessionRecord& r, const Pose& predicted, double since) const {
  if (!r.verification.accepted) return;
  const LocalizeConfig& lc = config_.localize;
  const double scale = std::max(1.0, config_.loop.sigma * since / lc.track_max_correction);
  const Pose difference = predicted.inverse() * r.pose;
  const double degrees = rotation_angle(difference) * 180 / M_PI;
  if (difference.translation().norm() <= scale * lc.track_max_correction && degrees <= scale * lc.track_max_correction_deg) {
    return;
  }
  r.verification.accepted = false;
  r.verification.reason = fmt::format("moves the link by {:.1f} m, {:.1f} deg (at most {:.1f} m, {:.1f} deg after {:.0f} m)",
                                      difference.translation().norm(), degrees, scale * lc.track_max_correction,
                                      scale * lc.track_max_correction_deg, since);
}

void SessionJoiner::search_loop(std::size_t q) {
  if (path_[q] - last_loop_ < config_.loop.search_interval_after_loop) return;
  const Pose predicted = orthonormalized(*base_from_joining_ * joining_.pose(q));
  const double radius = search_radius(gate_, path_[q] - last_loop_);
  const std::vector<PlaceQuery> query{{joining_.place(q), 0.0}};
  for (const PlaceProposal& c : propose_places(base_, places_, query, base_.near(predicted.translation(), radius), search_)) {
    CrossSessionRecord r = verify(q, c, {orthonormalized(base_.pose(c.keyframe).inverse() * predicted)}, verification_);
    require_link_agrees(r, predicted, path_[q] - last_loop_);
    const bool accepted = r.verification.accepted;
    r.outcome = accepted ? "loop" : "rejected loop";
    if (accepted) {
      edges_.push_back(edge_of(r));
      base_from_joining_ = orthonormalized(r.pose * joining_.pose(q).inverse());
      last_loop_ = path_[q];
    }
    records_.push_back(std::move(r));
    if (accepted) return;
  }
}

}  // namespace

JoinedMaps SessionJoiner::assemble() const {
  const SavedMap& a = base_.saved();
  const SavedMap& b = joining_.saved();
  JoinedMaps out;
  out.base_keyframes = a.keyframes.size();
  out.map.manifest = a.manifest;
  out.map.config = config_;
  out.map.manifest.sessions = map_sessions(a);
  const auto offset = static_cast<std::uint32_t>(out.map.manifest.sessions.size());
  for (MapSession s : map_sessions(b)) {
    s.linked = s.linked && linked_at_.has_value();
    out.map.manifest.sessions.push_back(s);
  }
  out.map.keyframes = a.keyframes;
  for (MapKeyframe kf : b.keyframes) {
    kf.session += offset;
    out.map.keyframes.push_back(kf);
  }
  out.map.edges = a.edges;
  for (PoseGraphEdge e : b.edges) {
    e.from += out.base_keyframes;
    e.to += out.base_keyframes;
    out.map.edges.push_back(e);
  }
  for (const CrossEdge& e : edges_) {
    out.map.edges.push_back({e.base, out.base_keyframes + e.joining, e.measured, e.information, EdgeKind::kLoop});
  }
  out.map.places = a.places;
  out.map.places.insert(out.map.places.end(), b.places.begin(), b.places.end());
  out.records = records_;
  out.linked_at = linked_at_;
  out.linked_after = linked_at_ ? path_[*linked_at_] : 0.0;
  out.cross_session_loops = edges_.size();
  return out;
}

std::vector<Pose> SessionJoiner::optimize(JoinedMaps& out) const {
  // Nodes: the keyframes in the base frame (linked sessions), the joining
  // ones carried there by the link; base keyframe 0 first (held fixed).
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::vector<std::size_t> node(out.map.keyframes.size(), kNone);
  PoseGraph graph;
  for (std::size_t k = 0; k < out.map.keyframes.size(); ++k) {
    if (!session_linked(out.map, k)) continue;
    const Pose& pose = out.map.keyframes[k].pose;
    node[k] = graph.add_node(k < out.base_keyframes ? pose : orthonormalized(initial_link_ * pose));
  }
  for (const PoseGraphEdge& e : out.map.edges) {
    if (node[e.from] != kNone && node[e.to] != kNone) graph.add_edge({node[e.from], node[e.to], e.measured, e.information, e.kind});
  }
  // The joining poses start where the link puts them, as far from the
  // solution as the joining map drifted: more iterations than an
  // incremental optimisation of the SLAM needs.
  PoseGraphOptions options = PoseGraphOptions::from_config(config_.slam);
  options.max_iterations = std::max(options.max_iterations, kJoinIterations);
  out.optimization = graph.optimize(options);
  std::vector<Pose> poses(out.map.keyframes.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    poses[k] = node[k] != kNone ? graph.pose(node[k]) : out.map.keyframes[k].pose;
  }
  return poses;
}

JoinedMaps join_maps(const PriorMap& base, const PriorMap& joining, const SaloamConfig& config,
                     const PlaceRecognizer& places) {
  if (base.saved().manifest.detector != joining.saved().manifest.detector) {
    throw InputError(joining.saved().folder,
                     fmt::format("its descriptors are for the detector \"{}\", the base map's for \"{}\": they cannot "
                                 "be compared", joining.saved().manifest.detector, base.saved().manifest.detector));
  }
  SessionJoiner joiner(base, joining, config, places);
  return joiner.run();
}

void write_joined_map(const std::filesystem::path& folder, const JoinedMaps& joined, const PriorMap& base,
                      const PriorMap& joining) {
  std::shared_ptr<const StoredFeatures> held;
  write_map(folder, joined.map, [&](std::size_t k) -> const StoredFeatures& {
    held = k < joined.base_keyframes ? base.features(k) : joining.features(k - joined.base_keyframes);
    return *held;
  });
}

}  // namespace saloam
