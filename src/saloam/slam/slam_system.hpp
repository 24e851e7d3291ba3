#pragma once
// SA-LOAM as one system (the paper's Fig. 2): the semantic odometry and
// place recognition side by side, the back end above them. Per frame:
//
//   odometry_pose = odometry.register_frame(scan)
//   if a keyframe is due:   describe the place, keep the features, add a graph node
//   if a search is due:     the place search (place_search.hpp) over the
//                           earlier keyframes: candidates (Eq. 3) -> scores
//                           of the keyframe's descriptor (and, with
//                           loop.lateral_query_offset, of the scan seen
//                           from either side) (> threshold, best N_loop) -> geometric
//                           verification -> loop edge -> optimise
//
// Keyframes (every `slam.keyframe_distance` metres or `keyframe_angle_deg`
// degrees) are the pose graph's nodes and the only frames searched for or
// returned as loops; every other frame rides on its keyframe with its
// odometry offset. The graph is optimised as soon as a loop is accepted (in
// the same run, as the paper does), so later candidates are searched around
// corrected poses. Everything runs on the caller's thread (the odometry may
// use more, per its config): the output does not depend on timing.

#include <cstddef>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/odometry/semantic_odometry.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/slam/loop_candidates.hpp"
#include "saloam/slam/loop_verification.hpp"
#include "saloam/slam/place_search.hpp"
#include "saloam/slam/pose_graph.hpp"

namespace saloam {

/// A keyframe's odometry features, stored compactly (float, sensor frame at
/// the pose instant) for the submaps of geometric verification.
struct StoredFeatures {
  std::vector<Eigen::Vector3f> edge_points, planar_points;
  std::vector<ClassIndex> edge_classes, planar_classes;

  static StoredFeatures from(const ScanFeatures& features);
  [[nodiscard]] ScanFeatures expand() const;
  [[nodiscard]] std::size_t bytes() const;
};

struct Keyframe {
  std::size_t frame = 0;       ///< index of the frame in processing order
  double timestamp = 0;
  double travelled = 0;        ///< [m] odometry path length up to this frame
  Pose odometry_pose = Pose::Identity();
  StoredFeatures features;
  /// The keyframe's scan turned level (level_rotation of up in its frame):
  /// `place` describes it so, and a place match's guess is turned back.
  Eigen::Matrix3d level = Eigen::Matrix3d::Identity();
  PlaceDescriptor place;
};

/// The live SLAM's keyframes as the place search sees them: one session,
/// poses at the pose graph's current estimates, features kept in memory.
class LiveKeyframes final : public KeyframeSet {
 public:
  LiveKeyframes(const std::vector<Keyframe>& keyframes, const PoseGraph& graph) : keyframes_(keyframes), graph_(graph) {}
  [[nodiscard]] std::size_t size() const override { return keyframes_.size(); }
  [[nodiscard]] Pose pose(std::size_t k) const override { return graph_.pose(k); }
  [[nodiscard]] std::uint32_t session(std::size_t /*k*/) const override { return 0; }
  [[nodiscard]] bool in_frame(std::size_t /*k*/) const override { return true; }
  [[nodiscard]] const PlaceDescriptor& place(std::size_t k) const override { return keyframes_[k].place; }
  [[nodiscard]] Eigen::Matrix3d level(std::size_t k) const override { return keyframes_[k].level; }
  [[nodiscard]] ScanFeatures scan_features(std::size_t k) const override { return keyframes_[k].features.expand(); }
  [[nodiscard]] std::vector<std::size_t> near(const Eigen::Vector3d& position, double radius) const override;

 private:
  const std::vector<Keyframe>& keyframes_;
  const PoseGraph& graph_;
};

/// One verified loop candidate (a row of loops.csv).
struct LoopRecord {
  std::size_t query_keyframe = 0, match_keyframe = 0;
  std::size_t query_frame = 0, match_frame = 0;
  double travelled = 0;  ///< [m] between the two
  PlaceMatch score;
  bool by_proximity = false;  ///< proposed because the estimate put it within loop.proximity_radius
  double query_offset = 0;    ///< [m] proposed for the query described this far to the left (loop.lateral_query_offset)
  LoopVerification verification;
};

/// Wall time of each part of one frame [ms].
struct SlamFrameTimings {
  double odometry_ms = 0;
  double place_ms = 0;         ///< descriptor of a new keyframe
  double search_ms = 0;        ///< candidates and scoring
  double verification_ms = 0;
  double optimization_ms = 0;
  [[nodiscard]] double loop_ms() const { return place_ms + search_ms + verification_ms + optimization_ms; }
  [[nodiscard]] double total_ms() const { return odometry_ms + loop_ms(); }
};

class SlamSystem {
 public:
  /// `network`: the SGPR weights, required when loop.detector uses SGPR.
  SlamSystem(const SaloamConfig& config, std::optional<SgprNetwork> network);
  ~SlamSystem();
  SlamSystem(const SlamSystem&) = delete;
  SlamSystem& operator=(const SlamSystem&) = delete;

  /// Processes the next scan; returns its odometry pose (T_world<-sensor).
  Pose process(const LabelledCloud& scan, double timestamp);

  /// Every frame's pose after loop closure (world = first frame).
  [[nodiscard]] std::vector<Pose> optimized_poses() const;
  /// Every frame's pose with the keyframes at `keyframe_poses` (one per
  /// keyframe, e.g. after a joint optimisation with another map): each frame
  /// rides on its keyframe with its odometry offset.
  [[nodiscard]] std::vector<Pose> optimized_poses(const std::vector<Pose>& keyframe_poses) const;
  /// Frame `frame`'s pose after loop closure (an element of optimized_poses()).
  [[nodiscard]] Pose optimized_pose(std::size_t frame) const;
  [[nodiscard]] const std::vector<Pose>& odometry_poses() const { return odometry_.poses(); }
  [[nodiscard]] const std::vector<double>& timestamps() const { return odometry_.timestamps(); }
  [[nodiscard]] const SemanticOdometry& odometry() const { return odometry_; }
  [[nodiscard]] const std::vector<Keyframe>& keyframes() const { return keyframes_; }
  /// Current estimate of keyframe k.
  [[nodiscard]] Pose keyframe_pose(std::size_t k) const { return graph_.pose(k); }
  [[nodiscard]] const std::vector<LoopRecord>& loops() const { return loops_; }
  [[nodiscard]] std::size_t accepted_loops() const { return accepted_; }
  [[nodiscard]] const std::vector<SlamFrameTimings>& timings() const { return timings_; }
  [[nodiscard]] const PoseGraph& graph() const { return graph_; }
  [[nodiscard]] std::size_t optimizations() const { return optimizations_; }
  /// Bytes held per keyframe for loop closure (features and descriptors), summed.
  [[nodiscard]] std::size_t keyframe_bytes() const;

 private:
  [[nodiscard]] bool keyframe_due(const Pose& odometry_pose) const;
  void add_keyframe(const LabelledCloud& scan, const Pose& odometry_pose, double timestamp, SlamFrameTimings& timing);
  [[nodiscard]] bool search_due() const;
  void close_loops(const LabelledCloud& scan, SlamFrameTimings& timing);
  [[nodiscard]] std::vector<std::size_t> select_candidates(std::size_t query);
  /// `sideways`: the query scan described from either side (none: the keyframe's descriptor only).
  [[nodiscard]] std::vector<PlaceProposal> propose(std::size_t query, const std::vector<std::size_t>& candidates,
                                                   const std::vector<PlaceQuery>& sideways) const;
  [[nodiscard]] LoopRecord verify(std::size_t query, const PlaceProposal& proposal) const;
  void add_loop_edge(const LoopRecord& record);
  void optimize();
  /// Edge information from a registration: scale * (H / N + eps I).
  [[nodiscard]] Matrix6d information_of(const RegistrationResult& registration, double frames) const;

  SaloamConfig config_;
  SemanticOdometry odometry_;
  PlaceRecognizer places_;
  CandidateGate gate_;
  LoopVerificationSettings verification_;
  PoseGraphOptions graph_options_;
  PlaceSearchOptions search_;  ///< every keyframe its own place (same_place_distance 0)
  std::mt19937_64 rng_;

  PoseGraph graph_;
  std::vector<Keyframe> keyframes_;
  std::vector<KeyframePlace> keyframe_places_;  ///< positions at the current estimates
  std::vector<std::size_t> frame_keyframe_;     ///< per frame: the keyframe it rides on
  LiveKeyframes live_{keyframes_, graph_};
  std::vector<LoopRecord> loops_;
  std::size_t accepted_ = 0;
  std::size_t optimizations_ = 0;
  double travelled_ = 0;
  double last_loop_travelled_ = -1e300;  ///< path length at the last accepted loop
  std::vector<SlamFrameTimings> timings_;
};

}  // namespace saloam
