#include "saloam/slam/slam_system.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "saloam/core/lie.hpp"
#include "saloam/core/profiling.hpp"

namespace saloam {

namespace {
void append(const FeatureCloud& cloud, std::vector<Eigen::Vector3f>& points, std::vector<ClassIndex>& classes) {
  points.reserve(cloud.size());
  for (const auto& p : cloud.points) points.push_back(p.cast<float>());
  classes = cloud.classes;
}

void expand_into(const std::vector<Eigen::Vector3f>& points, const std::vector<ClassIndex>& classes, FeatureCloud& out) {
  out.points.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) out.push_back(points[i].cast<double>(), classes[i], 0.0F);
}
}  // namespace

StoredFeatures StoredFeatures::from(const ScanFeatures& features) {
  StoredFeatures s;
  append(features.edges, s.edge_points, s.edge_classes);
  append(features.planars, s.planar_points, s.planar_classes);
  return s;
}

ScanFeatures StoredFeatures::expand() const {
  ScanFeatures f;
  expand_into(edge_points, edge_classes, f.edges);
  expand_into(planar_points, planar_classes, f.planars);
  return f;
}

std::size_t StoredFeatures::bytes() const {
  return (edge_points.size() + planar_points.size()) * (sizeof(Eigen::Vector3f) + sizeof(ClassIndex));
}

std::vector<std::size_t> LiveKeyframes::near(const Eigen::Vector3d& position, double radius) const {
  std::vector<std::size_t> found;
  for (std::size_t k = 0; k < keyframes_.size(); ++k) {
    if ((graph_.pose(k).translation() - position).norm() <= radius) found.push_back(k);
  }
  return found;
}

SlamSystem::SlamSystem(const SaloamConfig& config, std::optional<SgprNetwork> network)
    : config_(config),
      odometry_(config.odometry),
      places_(PlaceRecognizer::from_config(config.loop, std::move(network))),
      gate_(CandidateGate::from_config(config.loop)),
      verification_(LoopVerificationSettings::from_config(config)),
      graph_options_(PoseGraphOptions::from_config(config.slam)),
      search_(PlaceSearchOptions::from_config(config, places_.detector(), 0.0)),
      rng_(config.loop.seed) {}

SlamSystem::~SlamSystem() = default;

Pose SlamSystem::process(const LabelledCloud& scan, double timestamp) {
  SlamFrameTimings timing;
  const StageTimer timer;
  const std::size_t previous = odometry_.poses().size();
  const Pose odometry_pose = odometry_.register_frame(scan, timestamp);
  timing.odometry_ms = timer.elapsed_ms();
  if (previous > 0) travelled_ += (odometry_.poses()[previous - 1].translation() - odometry_pose.translation()).norm();

  if (keyframe_due(odometry_pose)) {
    add_keyframe(scan, odometry_pose, timestamp, timing);
    if (search_due()) close_loops(scan, timing);
  }
  frame_keyframe_.push_back(keyframes_.size() - 1);
  timings_.push_back(timing);
  return odometry_pose;
}

bool SlamSystem::keyframe_due(const Pose& odometry_pose) const {
  if (keyframes_.empty()) return true;
  const Keyframe& last = keyframes_.back();
  const Pose moved = last.odometry_pose.inverse() * odometry_pose;
  return travelled_ - last.travelled >= config_.slam.keyframe_distance ||
         rotation_angle(moved) >= config_.slam.keyframe_angle_deg * M_PI / 180.0;
}

void SlamSystem::add_keyframe(const LabelledCloud& scan, const Pose& odometry_pose, double timestamp,
                              SlamFrameTimings& timing) {
  const StageTimer timer;
  Keyframe kf;
  kf.frame = odometry_.poses().size() - 1;
  kf.timestamp = timestamp;
  kf.travelled = travelled_;
  kf.odometry_pose = odometry_pose;
  kf.features = StoredFeatures::from(odometry_.last_features());
  // Described level (gravity.hpp): a tilted sensor's rings and sectors then
  // lie as a level one's, and a revisit in the other direction matches.
  const Eigen::Vector3d up = odometry_pose.linear().transpose() * odometry_.up();
  if (points_up(up)) {
    kf.place = places_.describe(scan);
  } else {
    kf.level = level_rotation(up);
    kf.place = places_.describe(turned(scan, kf.level));
  }

  if (keyframes_.empty()) {
    graph_.add_node(odometry_pose);
  } else {
    // The new node continues from the previous one's current (corrected)
    // estimate with the odometry's motion in between.
    const std::size_t prev = keyframes_.size() - 1;
    const Pose odometry_step = keyframes_.back().odometry_pose.inverse() * odometry_pose;
    const std::size_t node = graph_.add_node(orthonormalized(graph_.pose(prev) * odometry_step));
    const double frames = static_cast<double>(kf.frame - keyframes_.back().frame);
    graph_.add_edge({prev, node, odometry_step, information_of(odometry_.last_frame_stats().registration, frames),
                     EdgeKind::kOdometry});
  }
  keyframe_places_.push_back({graph_.pose(keyframes_.size()).translation(), travelled_});
  keyframes_.push_back(std::move(kf));
  timing.place_ms = timer.elapsed_ms();
}

bool SlamSystem::search_due() const {
  return travelled_ - last_loop_travelled_ >= config_.loop.search_interval_after_loop;
}

void SlamSystem::close_loops(const LabelledCloud& scan, SlamFrameTimings& timing) {
  StageTimer timer;
  const std::size_t query = keyframes_.size() - 1;
  const std::vector<std::size_t> candidates = select_candidates(query);
  const Eigen::Matrix3d& level = keyframes_[query].level;
  const std::vector<PlaceQuery> sideways =
      level.isIdentity() ? sideways_queries(places_, scan, config_.loop.lateral_query_offset)
                         : sideways_queries(places_, turned(scan, level), config_.loop.lateral_query_offset);
  const std::vector<PlaceProposal> proposals = propose(query, candidates, sideways);
  timing.search_ms = timer.lap().wall_ms;

  bool closed = false;
  // Best score first; the first accepted loop ends the search: the others
  // would constrain the same stretch again.
  for (const PlaceProposal& proposal : proposals) {
    LoopRecord record = verify(query, proposal);
    const bool accepted = record.verification.accepted;
    loops_.push_back(std::move(record));
    if (accepted) {
      add_loop_edge(loops_.back());
      closed = true;
      break;
    }
  }
  timing.verification_ms = timer.lap().wall_ms;
  if (closed) {
    optimize();
    timing.optimization_ms = timer.lap().wall_ms;
  }
}

std::vector<std::size_t> SlamSystem::select_candidates(std::size_t query) {
  const std::span<const KeyframePlace> earlier(keyframe_places_.data(), query);
  return loop_candidates(keyframe_places_[query], earlier, gate_, rng_);
}

std::vector<PlaceProposal> SlamSystem::propose(std::size_t query, const std::vector<std::size_t>& candidates,
                                               const std::vector<PlaceQuery>& sideways) const {
  const ScoredCandidates scored = score_candidates(live_, places_, keyframes_[query].place, candidates);
  std::vector<PlaceProposal> proposals = rank_places(live_, scored, search_);
  // Beyond the paper (loop.lateral_query_offset): the scan described from a
  // lane width to either side too, the best N_loop over the three queries
  // (a reverse revisit in the other lane scores low from the sensor).
  if (!sideways.empty()) {
    for (PlaceProposal& p : propose_places(live_, places_, sideways, candidates, search_)) proposals.push_back(p);
    proposals = merge_proposals(live_, std::move(proposals), search_);
  }
  // Beyond the paper: the candidate nearest to the query by the current
  // estimate, when nearer than proximity_radius, is verified too, whatever
  // its score (descriptors lose similarity on reverse revisits in the other
  // lane; the estimate, corrected by earlier loops, still knows the place).
  if (config_.loop.proximity_radius > 0) {
    add_nearest(proposals, live_, scored, keyframe_places_[query].position, config_.loop.proximity_radius);
  }
  return proposals;
}

LoopRecord SlamSystem::verify(std::size_t query, const PlaceProposal& proposal) const {
  const std::size_t match = proposal.keyframe;
  // The submap: keyframes around the match (never the query's own recent
  // past), placed by the current estimates relative to the match.
  const std::size_t w = static_cast<std::size_t>(std::max(0, config_.loop.submap_half_width));
  const double recent = 0.5 * gate_.exclude_recent_distance;
  const LoopSubmap submap = submap_around(live_, match, w, verification_, query, [&](std::size_t k) {
    return keyframes_[query].travelled - keyframes_[k].travelled >= recent;
  });
  // Initial guesses: the current estimates, and the descriptor's yaw (with
  // its x-y offset when it gives one, SSC's) in place.
  // A query from the side: the descriptor's guess moved back to the sensor.
  // The descriptors' guesses are between the level frames: turned back.
  std::vector<Pose> guesses{orthonormalized(graph_.pose(match).inverse() * graph_.pose(query))};
  const auto sensor_guess = [&](const Pose& level_guess) {
    return sensor_frame_guess(level_guess, keyframes_[match].level, keyframes_[query].level);
  };
  if (proposal.query_offset != 0) {
    add_distinct_guess(guesses, sensor_guess(proposal.lateral_guess()));
  } else if (proposal.match.yaw) {
    add_distinct_guess(guesses, sensor_guess(place_match_guess(proposal.match)));
  }
  LoopRecord record;
  record.query_keyframe = query;
  record.match_keyframe = match;
  record.query_frame = keyframes_[query].frame;
  record.match_frame = keyframes_[match].frame;
  record.travelled = keyframes_[query].travelled - keyframes_[match].travelled;
  record.score = proposal.match;
  record.by_proximity = proposal.by_proximity;
  record.query_offset = proposal.query_offset;
  // Up in the match's frame for the plane constraint and the level lines.
  record.verification = verify_loop(keyframes_[query].features.expand(), submap, guesses,
                                    with_up(verification_, keyframes_[match].odometry_pose.linear().transpose() * odometry_.up()));
  return record;
}

void SlamSystem::add_loop_edge(const LoopRecord& record) {
  graph_.add_edge({record.match_keyframe, record.query_keyframe, record.verification.relative,
                   information_of(record.verification.registration, 1.0), EdgeKind::kLoop});
  ++accepted_;
  last_loop_travelled_ = travelled_;
}

void SlamSystem::optimize() {
  graph_.optimize(graph_options_);
  ++optimizations_;
  for (std::size_t k = 0; k < keyframes_.size(); ++k) keyframe_places_[k].position = graph_.pose(k).translation();
}

Matrix6d SlamSystem::information_of(const RegistrationResult& registration, double frames) const {
  return registration_information(registration, frames, config_.slam.information_scale);
}

std::vector<Pose> SlamSystem::optimized_poses() const {
  std::vector<Pose> keyframe_poses(keyframes_.size());
  for (std::size_t k = 0; k < keyframes_.size(); ++k) keyframe_poses[k] = graph_.pose(k);
  return optimized_poses(keyframe_poses);
}

std::vector<Pose> SlamSystem::optimized_poses(const std::vector<Pose>& keyframe_poses) const {
  if (keyframe_poses.size() != keyframes_.size()) throw std::invalid_argument("one pose per keyframe is needed");
  std::vector<Pose> poses;
  const auto& odometry = odometry_.poses();
  poses.reserve(odometry.size());
  for (std::size_t f = 0; f < frame_keyframe_.size(); ++f) {
    const Keyframe& kf = keyframes_[frame_keyframe_[f]];
    poses.push_back(orthonormalized(keyframe_poses[frame_keyframe_[f]] * (kf.odometry_pose.inverse() * odometry[f])));
  }
  return poses;
}

Pose SlamSystem::optimized_pose(std::size_t frame) const {
  const std::size_t k = frame_keyframe_.at(frame);
  return orthonormalized(graph_.pose(k) * (keyframes_[k].odometry_pose.inverse() * odometry_.poses()[frame]));
}

std::size_t SlamSystem::keyframe_bytes() const {
  std::size_t bytes = 0;
  for (const auto& kf : keyframes_) {
    bytes += sizeof(Keyframe) + kf.features.bytes();
    bytes += kf.place.graph.size() * (sizeof(int) + sizeof(Eigen::Vector3d));
    bytes += static_cast<std::size_t>(kf.place.context.descriptor.size() + kf.place.context.unit_columns.size() +
                                      kf.place.context.ring_key.size()) *
             sizeof(float);
    bytes += kf.place.ssc.bytes();
  }
  return bytes;
}

}  // namespace saloam
