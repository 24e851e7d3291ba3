#pragma once
// Geometric verification of a loop candidate (paper Sec. III-C): the
// semantic-assisted ICP of the odometry registers the query keyframe's
// features against a submap of the keyframes around the candidate, and the
// registration's fit decides.
//
// Frames: the submap is expressed in the candidate keyframe's sensor frame;
// the result is T_candidate<-query. Registration runs coarse to fine (a wide
// correspondence radius and every third feature first, then the odometry's
// radius and all features), from each initial guess
// given (the current pose estimates, which drift, and a descriptor's yaw,
// which survives drift and reverse-direction revisits), in order: the first
// accepted fit ends the search, else the fit with the most inliers is reported.
//
// Two acceptance tests, both always computed:
//  - "loss", the paper's: r < delta_r, r being Eq. 2's weighted sum of
//    point-to-line and point-to-plane distances over all correspondences. It
//    grows with the number of features a scan has.
//  - "normalized": the mean residual of the inliers, the fraction of the
//    query's features that found an inlier correspondence, and the smallest
//    eigenvalue of the translation block of the Hessian per correspondence
//    (a straight road with nothing across it constrains no translation along
//    it: such a fit may not be trusted), and uniqueness: fits started a few
//    metres along the least constrained direction must not find another
//    solution nearly as good (rows of trees or parked cars repeat along a
//    street; on reverse revisits such a second solution fooled the fit).

#include <limits>
#include <span>
#include <string>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/odometry/local_map.hpp"
#include "saloam/odometry/registration.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/slam/pose_graph.hpp"

namespace saloam {

/// Built from the configuration (loop.* and odometry.*), which holds the
/// defaults; a default-constructed value is all zeros.
struct LoopVerificationSettings {
  RegistrationSettings coarse;  ///< wide radius, loose kernel: converges from metres off
  RegistrationSettings fine;    ///< the odometry's settings, more iterations
  ClassVoxelSizes voxel_size{};
  bool loss_test{};             ///< true: the paper's r < delta_r decides; false: the normalized test
  double delta_r{};
  double max_mean_residual{};
  double min_inlier_fraction{};
  double min_translation_eigenvalue{};
  double max_runner_up_ratio{};  ///< .inf: test off

  static LoopVerificationSettings from_config(const SaloamConfig& config);
};

/// Features of the keyframes around a candidate, in the candidate's sensor
/// frame, indexed at the coarse and the fine radius.
class LoopSubmap {
 public:
  explicit LoopSubmap(const LoopVerificationSettings& settings);
  /// Adds one keyframe's features given in its own sensor frame, with
  /// T_candidate<-keyframe.
  void add(const ScanFeatures& features, const Pose& candidate_from_keyframe);
  [[nodiscard]] const SemanticLocalMap& coarse() const { return coarse_; }
  [[nodiscard]] const SemanticLocalMap& fine() const { return fine_; }

 private:
  SemanticLocalMap coarse_, fine_;
};

struct LoopVerification {
  Pose relative = Pose::Identity();  ///< T_candidate<-query, registered
  RegistrationResult registration;   ///< the fine registration of the winning guess
  std::size_t guess = 0;             ///< index of the winning initial guess
  std::size_t features = 0;          ///< features of the query
  double inlier_fraction = 0;
  double mean_residual = 0;          ///< [m] mean |residual| of the inliers
  double translation_eigenvalue = 0; ///< smallest eigenvalue of H_tt / N
  /// Inliers of the best distinct other fit over the best fit's (0: none
  /// found, the test is off, or the fit fails the rest of the normalized test).
  double runner_up_inlier_ratio = 0;
  bool passes_loss_test = false;
  bool passes_normalized_test = false;
  bool accepted = false;
  std::string reason;                ///< why it was rejected (empty when accepted)
};

/// Registers `query` (sensor frame) to the submap from each guess
/// (T_candidate<-query) and applies the acceptance tests.
LoopVerification verify_loop(const ScanFeatures& query, const LoopSubmap& submap, std::span<const Pose> guesses,
                             const LoopVerificationSettings& settings);

/// The initial guess a place match gives for T_candidate<-query: its yaw
/// about z and, when the descriptor gives one (SSC), its x-y offset;
/// identity without either.
Pose place_match_guess(const PlaceMatch& match);

/// True when two fits of one query lie within 0.5 m and 2 degrees of each
/// other: the verification counts them one solution (its uniqueness test).
bool same_fit(const Pose& a, const Pose& b);

/// Appends `guess` unless a guess already in `guesses` lies within 1 m and
/// 5 degrees of it (the registration would converge to the same fit).
void add_distinct_guess(std::vector<Pose>& guesses, const Pose& guess);

/// Information of a loop or odometry edge from its registration:
/// scale / max(1, frames) * (H / N + 1e-3 * trace(H / N) / 6 * I), H the
/// Gauss-Newton Hessian and N the correspondence count (a typical scan's
/// per-correspondence information when the registration failed).
Matrix6d registration_information(const RegistrationResult& registration, double frames, double scale);

}  // namespace saloam
