// Synthetic trajectories with known errors for the KITTI, ATE and RPE metrics.

#include "saloam/eval/trajectory_metrics.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "saloam/core/lie.hpp"

namespace saloam {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

Pose make_pose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Pose T = Pose::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

Eigen::Matrix3d rot_z(double angle) { return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

/// Straight drive of `frames` poses spaced `step` metres along the body x axis
/// of a fixed, non-trivial orientation (so no axis is special).
std::vector<Pose> straight_path(std::size_t frames, double step) {
  const Eigen::Matrix3d R0 = (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()))
                                 .toRotationMatrix();
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < frames; ++i) {
    poses.push_back(make_pose(R0, R0 * Eigen::Vector3d(step * static_cast<double>(i), 0, 0) + Eigen::Vector3d(5, -3, 1)));
  }
  return poses;
}

/// A winding drive: constant speed, yaw rate varying along the path, gentle
/// pitch, so that all metrics see rotation and translation.
std::vector<Pose> winding_path(std::size_t frames, double step) {
  std::vector<Pose> poses{Pose::Identity()};
  for (std::size_t i = 1; i < frames; ++i) {
    const double s = static_cast<double>(i);
    const Eigen::Matrix3d dR = (Eigen::AngleAxisd(0.02 * std::sin(0.01 * s), Eigen::Vector3d::UnitZ()) *
                                Eigen::AngleAxisd(0.002 * std::cos(0.013 * s), Eigen::Vector3d::UnitY()))
                                   .toRotationMatrix();
    poses.push_back(orthonormalized(poses.back() * make_pose(dR, Eigen::Vector3d(step, 0, 0))));
  }
  return poses;
}

TEST(KittiMetrics, TrajectoryDistancesAccumulatePathLength) {
  const auto poses = straight_path(11, 0.5);
  const auto dist = trajectory_distances(poses);
  ASSERT_EQ(dist.size(), 11u);
  EXPECT_DOUBLE_EQ(dist[0], 0.0);
  EXPECT_NEAR(dist[10], 5.0, 1e-12);
  EXPECT_TRUE(trajectory_distances({}).empty());
}

TEST(KittiMetrics, OnePercentScaleErrorGivesOnePercentTranslationError) {
  const auto gt = straight_path(9000, 0.1);  // 900 m: every length 100..800 fits
  std::vector<Pose> est = gt;
  for (auto& T : est) T.translation() *= 1.01;
  const auto m = compute_kitti_metrics(gt, est);
  // A segment ends at the first frame strictly beyond its length, so it is up
  // to one 0.1 m step longer: 1 % within 0.15 % of itself.
  EXPECT_NEAR(m.t_err_percent, 1.0, 1.5e-3);
  EXPECT_NEAR(m.r_err_deg_per_100m, 0.0, 1e-5);
  ASSERT_EQ(m.per_length.size(), 8u);
  std::size_t total = 0;
  for (const auto& l : m.per_length) {
    EXPECT_GT(l.segments, 0u) << l.length_m;
    EXPECT_NEAR(l.t_err_percent, 1.0, 1.5e-3) << l.length_m;
    total += l.segments;
  }
  EXPECT_EQ(total, m.segments);
  // First frames every 10th frame; a 100 m segment fits from frames 0..7990 (strictly beyond 100 m).
  EXPECT_EQ(m.per_length[0].segments, 800u);
  EXPECT_EQ(m.per_length[7].segments, 100u);
}

TEST(KittiMetrics, ConstantYawDriftGivesItsDegreesPer100m) {
  const double drift_deg_per_100m = 2.0;
  const double step = 0.1;
  const auto gt = straight_path(9000, step);
  // The estimate turns by an extra, constant yaw per metre driven.
  std::vector<Pose> est{gt.front()};
  const Pose increment = make_pose(rot_z(drift_deg_per_100m * kDegToRad / 100.0 * step), Eigen::Vector3d(step, 0, 0));
  for (std::size_t i = 1; i < gt.size(); ++i) est.push_back(orthonormalized(est.back() * increment));
  const auto m = compute_kitti_metrics(gt, est);
  EXPECT_NEAR(m.r_err_deg_per_100m, drift_deg_per_100m, 2e-3 * drift_deg_per_100m);
  for (const auto& l : m.per_length) EXPECT_NEAR(l.r_err_deg_per_100m, drift_deg_per_100m, 2e-3 * drift_deg_per_100m);
  EXPECT_GT(m.t_err_percent, 0.1);  // turning away also displaces the end point
}

TEST(KittiMetrics, IdenticalTrajectoriesGiveZero) {
  const auto gt = winding_path(2000, 0.8);
  const auto m = compute_kitti_metrics(gt, gt);
  ASSERT_GT(m.segments, 0u);
  EXPECT_NEAR(m.t_err_percent, 0.0, 1e-9);
  // acos near 1 resolves ~1e-8 rad: "zero" rotation is ~1e-6 deg/100 m.
  EXPECT_NEAR(m.r_err_deg_per_100m, 0.0, 1e-5);
}

TEST(KittiMetrics, ShortPathHasNoSegments) {
  const auto gt = straight_path(50, 1.0);
  const auto m = compute_kitti_metrics(gt, gt);
  EXPECT_EQ(m.segments, 0u);
  EXPECT_TRUE(std::isnan(m.t_err_percent));
  EXPECT_TRUE(std::isnan(m.r_err_deg_per_100m));
  for (const auto& l : m.per_length) EXPECT_EQ(l.segments, 0u);
}

TEST(KittiMetrics, CustomLengthsAndStep) {
  // Integer positions: distances are exact, so the strict "beyond" rule is testable.
  std::vector<Pose> gt;
  for (int i = 0; i <= 100; ++i) gt.push_back(make_pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(i, 0, 0)));
  KittiOptions options;
  options.lengths_m = {10, 20};
  options.step_frames = 5;
  const auto m = compute_kitti_metrics(gt, gt, options);
  ASSERT_EQ(m.per_length.size(), 2u);
  // Start frames 0, 5, ..., 85 fit a 10 m segment (last frame = first + 11 <= 100).
  EXPECT_EQ(m.per_length[0].segments, 18u);
  EXPECT_EQ(m.segment_errors.front().last_frame, 11u);
}

TEST(KittiMetrics, RejectsDifferentSizes) {
  const auto gt = straight_path(20, 1.0);
  const std::vector<Pose> est(gt.begin(), gt.begin() + 10);
  EXPECT_THROW(compute_kitti_metrics(gt, est), std::invalid_argument);
}

TEST(Umeyama, RecoversKnownSimilarity) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  std::vector<Eigen::Vector3d> source, target;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  const Eigen::Vector3d t(10, -4, 2.5);
  const double s = 1.7;
  for (int i = 0; i < 100; ++i) {
    source.emplace_back(u(rng), u(rng), u(rng));
    target.push_back(s * R * source.back() + t);
  }
  const auto sim = umeyama_alignment(source, target, true);
  EXPECT_NEAR(sim.scale, s, 1e-9);
  EXPECT_TRUE(sim.rotation.isApprox(R, 1e-9));
  EXPECT_TRUE(sim.translation.isApprox(t, 1e-9));

  // Without scale, a rigid transform is recovered exactly.
  for (std::size_t i = 0; i < source.size(); ++i) target[i] = R * source[i] + t;
  const auto se3 = umeyama_alignment(source, target, false);
  EXPECT_DOUBLE_EQ(se3.scale, 1.0);
  EXPECT_TRUE(se3.rotation.isApprox(R, 1e-9));
  EXPECT_TRUE(se3.translation.isApprox(t, 1e-9));
}

TEST(Umeyama, NeverReturnsAReflection) {
  // Target is a mirror image of the source: the best proper rotation has det +1.
  std::vector<Eigen::Vector3d> source{{1, 0, 0}, {0, 2, 0}, {0, 0, 3}, {1, 1, 1}, {-2, 1, 0.5}};
  std::vector<Eigen::Vector3d> target;
  for (const auto& p : source) target.emplace_back(p.x(), p.y(), -p.z());
  const auto T = umeyama_alignment(source, target, false);
  EXPECT_NEAR(T.rotation.determinant(), 1.0, 1e-12);
  EXPECT_TRUE((T.rotation.transpose() * T.rotation).isIdentity(1e-12));
}

TEST(Umeyama, RejectsBadInput) {
  EXPECT_THROW(umeyama_alignment({}, {}, false), std::invalid_argument);
  EXPECT_THROW(umeyama_alignment({{0, 0, 0}}, {{0, 0, 0}, {1, 1, 1}}, false), std::invalid_argument);
}

TEST(ErrorStats, RmseMeanMedianMax) {
  const auto s = error_stats({3.0, 1.0, 4.0, 2.0});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4.0));
  EXPECT_DOUBLE_EQ(error_stats({5.0, 1.0, 3.0}).median, 3.0);
  EXPECT_TRUE(std::isnan(error_stats({}).rmse));
}

TEST(Ate, RigidlyMovedCopyHasZeroAlignedError) {
  const auto gt = winding_path(600, 1.0);
  const Pose offset = make_pose(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, -0.5, 1).normalized()).toRotationMatrix(),
                                Eigen::Vector3d(12, -7, 3));
  std::vector<Pose> est;
  for (const auto& T : gt) est.push_back(offset * T);

  const auto ate = compute_ate(gt, est, Alignment::kSE3);
  EXPECT_LT(ate.aligned.rmse, 1e-9);
  EXPECT_LT(ate.aligned.max, 1e-9);
  EXPECT_GT(ate.unaligned.rmse, 5.0);
  EXPECT_TRUE(ate.transform.rotation.isApprox(offset.linear().transpose(), 1e-9));
  EXPECT_TRUE(ate.transform.apply(offset).isApprox(Pose::Identity(), 1e-9));
  ASSERT_EQ(ate.aligned_errors.size(), gt.size());

  const auto none = compute_ate(gt, est, Alignment::kNone);
  EXPECT_DOUBLE_EQ(none.aligned.rmse, none.unaligned.rmse);

  // Relative metrics do not see a rigid offset at all.
  EXPECT_NEAR(compute_kitti_metrics(gt, est).t_err_percent, 0.0, 1e-9);
  EXPECT_NEAR(compute_rpe(gt, est).trans_rmse_m, 0.0, 1e-9);
}

TEST(Ate, KnownOffsetWithoutAlignment) {
  const auto gt = winding_path(100, 1.0);
  std::vector<Pose> est = gt;
  for (auto& T : est) T.translation() += Eigen::Vector3d(0.3, 0.4, 0.0);  // |offset| = 0.5 m
  const auto ate = compute_ate(gt, est, Alignment::kSE3);
  EXPECT_NEAR(ate.unaligned.rmse, 0.5, 1e-12);
  EXPECT_NEAR(ate.unaligned.median, 0.5, 1e-12);
  EXPECT_LT(ate.aligned.rmse, 1e-9);
}

TEST(Ate, Sim3RemovesScale) {
  const auto gt = winding_path(400, 1.0);
  std::vector<Pose> est;
  for (const auto& T : gt) {
    Pose scaled = T;
    scaled.translation() = 0.5 * T.translation() + Eigen::Vector3d(1, 2, 3);
    est.push_back(scaled);
  }
  const auto sim3 = compute_ate(gt, est, Alignment::kSim3);
  EXPECT_NEAR(sim3.transform.scale, 2.0, 1e-9);
  EXPECT_LT(sim3.aligned.rmse, 1e-8);
  const auto se3 = compute_ate(gt, est, Alignment::kSE3);
  EXPECT_GT(se3.aligned.rmse, 1.0);
}

// Issue #39: a static ground truth has no scale; sim3 refuses instead of
// scaling the estimate to a point (scale 0, ATE 0).
TEST(Ate, Sim3OnAStaticTrajectoryIsRefused) {
  std::vector<Pose> still(10, Pose::Identity()), moving;
  for (int i = 0; i < 10; ++i) {
    Pose p = Pose::Identity();
    p.translation() = Eigen::Vector3d(1.0 * i, 0.1 * i * i, 0.0);
    moving.push_back(p);
  }
  try {
    (void)compute_ate(still, moving, Alignment::kSim3);
    FAIL() << "sim3 on a static ground truth was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("the ground truth does not move"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)compute_ate(moving, still, Alignment::kSim3), std::invalid_argument);
  EXPECT_GT(compute_ate(still, moving, Alignment::kSE3).aligned.rmse, 1.0);  // se3 still scores it
}

TEST(Ate, AssociateByTimePairsTheNearestWithinTheTolerance) {
  const std::vector<double> gt{0.0, 0.1, 0.2, 0.3, 0.4, 0.5};
  const std::vector<double> est{0.099, 0.21, 0.35, 0.401, 0.9};
  const auto pairs = associate_by_time(gt, est, 0.02);
  const std::vector<std::pair<std::size_t, std::size_t>> expected{{1, 0}, {2, 1}, {4, 3}};
  EXPECT_EQ(pairs, expected);
  EXPECT_TRUE(associate_by_time(gt, {10.0, 11.0}, 0.02).empty());
  // Each ground-truth time once.
  EXPECT_EQ(associate_by_time({1.0}, {0.995, 1.0, 1.005}, 0.02).size(), 1u);
}

TEST(Ate, ParseAlignment) {
  EXPECT_EQ(parse_alignment("se3"), Alignment::kSE3);
  EXPECT_EQ(parse_alignment("SIM3"), Alignment::kSim3);
  EXPECT_EQ(parse_alignment("none"), Alignment::kNone);
  EXPECT_THROW(parse_alignment("affine"), std::invalid_argument);
  EXPECT_EQ(alignment_name(Alignment::kSim3), "sim3");
}

TEST(Rpe, TranslationPerturbationOfOneFrame) {
  std::vector<Pose> gt;
  for (int i = 0; i < 101; ++i) gt.push_back(make_pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(i, 0, 0)));
  std::vector<Pose> est = gt;
  const Eigen::Vector3d d(0.0, 0.06, 0.08);  // 0.1 m
  est[50].translation() += d;
  const auto rpe = compute_rpe(gt, est);
  ASSERT_EQ(rpe.trans_errors_m.size(), 100u);
  for (std::size_t k = 0; k < 100; ++k) {
    const double expected = (k == 49 || k == 50) ? 0.1 : 0.0;
    EXPECT_NEAR(rpe.trans_errors_m[k], expected, 1e-12) << k;
    EXPECT_NEAR(rpe.rot_errors_deg[k], 0.0, 1e-6) << k;
  }
  EXPECT_NEAR(rpe.trans_rmse_m, std::sqrt(2 * 0.01 / 100.0), 1e-12);
  EXPECT_NEAR(rpe.trans.max, 0.1, 1e-12);
}

TEST(Rpe, RotationPerturbationOfOneFrame) {
  const auto gt = winding_path(80, 1.0);
  std::vector<Pose> est = gt;
  const double angle_deg = 1.5;
  est[30] = est[30] * make_pose(Eigen::AngleAxisd(angle_deg * kDegToRad, Eigen::Vector3d(0, 1, 1).normalized())
                                    .toRotationMatrix(),
                                Eigen::Vector3d::Zero());
  const auto rpe = compute_rpe(gt, est);
  ASSERT_EQ(rpe.rot_errors_deg.size(), 79u);
  for (std::size_t k = 0; k < 79; ++k) {
    EXPECT_NEAR(rpe.rot_errors_deg[k], (k == 29 || k == 30) ? angle_deg : 0.0, 1e-5) << k;
  }
  EXPECT_NEAR(rpe.rot_rmse_deg, angle_deg * std::sqrt(2.0 / 79.0), 1e-5);
  // Pair 29->30 keeps its translation (the frame turned in place), 30->31 sees
  // the next 1 m step from a rotated frame: 2 sin(angle/2) m off.
  EXPECT_NEAR(rpe.trans_errors_m[29], 0.0, 1e-9);
  EXPECT_NEAR(rpe.trans_errors_m[30], 2.0 * std::sin(0.5 * angle_deg * kDegToRad), 1e-9);
}

TEST(Rpe, LargerDelta) {
  const auto gt = winding_path(50, 1.0);
  const auto rpe = compute_rpe(gt, gt, 10);
  EXPECT_EQ(rpe.delta, 10u);
  EXPECT_EQ(rpe.trans_errors_m.size(), 40u);
  EXPECT_NEAR(rpe.trans_rmse_m, 0.0, 1e-9);
  EXPECT_THROW(compute_rpe(gt, gt, 0), std::invalid_argument);
}

/// `gt` re-integrated with every frame's motion t (body frame) changed to
/// t + |t| (forward f + lateral l + vertical u), the axes of the LiDAR frame
/// (x forward, y left, z up): relative errors of known share.
std::vector<Pose> biased(const std::vector<Pose>& gt, double forward, double lateral, double vertical) {
  std::vector<Pose> est{gt.front()};
  for (std::size_t i = 1; i < gt.size(); ++i) {
    Pose motion = gt[i - 1].inverse() * gt[i];
    const double length = motion.translation().norm();
    motion.translation() += length * Eigen::Vector3d(forward, lateral, vertical);
    est.push_back(est.back() * motion);
  }
  return est;
}

/// Poses of a LiDAR-frame trajectory in a KITTI camera frame (x right, y down,
/// z forward): P = C Q C^-1, C the camera-from-LiDAR rotation.
std::vector<Pose> in_camera_frame(const std::vector<Pose>& lidar) {
  Eigen::Matrix3d R;
  R << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  const Pose C = make_pose(R, Eigen::Vector3d::Zero());
  std::vector<Pose> out;
  for (const auto& Q : lidar) out.push_back(C * Q * C.inverse());
  return out;
}

TEST(ScaleBias, StraightDriveGivesTheShareOfEachAxis) {
  const auto gt = straight_path(501, 1.0);
  const auto est = biased(gt, -0.001, 0.0005, -0.0002);
  for (const auto& [g, e] : {std::pair{gt, est}, std::pair{in_camera_frame(gt), in_camera_frame(est)}}) {
    const ScaleBias bias = compute_scale_bias(g, e);
    EXPECT_EQ(bias.windows, 50u);
    EXPECT_NEAR(bias.length_m, 500.0, 1e-9);
    EXPECT_NEAR(bias.forward_percent, -0.1, 1e-9);
    EXPECT_NEAR(bias.lateral_percent, 0.05, 1e-9);
    EXPECT_NEAR(bias.vertical_percent, -0.02, 1e-9);
  }
  EXPECT_EQ(body_up_axis(gt), Eigen::Vector3d::UnitZ());
  EXPECT_EQ(body_up_axis(in_camera_frame(gt)), -Eigen::Vector3d::UnitY());
}

TEST(ScaleBias, WindingDriveResolvesEachWindowInItsMotionFrame) {
  // Up to 0.2 rad of turn per 10-frame window: a window's chord leans up to
  // 0.1 rad off each frame's forward axis, which mixes the components by
  // up to 1 - cos(0.1) of themselves and sin(0.1) of each other (on average
  // less: the turns go both ways).
  const auto gt = winding_path(3000, 1.0);
  const auto est = biased(gt, -0.001, 0.0005, -0.0002);
  const ScaleBias bias = compute_scale_bias(gt, est);
  EXPECT_EQ(bias.windows, 299u);
  EXPECT_NEAR(bias.forward_percent, -0.1, 0.01);
  EXPECT_NEAR(bias.lateral_percent, 0.05, 0.01);
  EXPECT_NEAR(bias.vertical_percent, -0.02, 0.005);
}

TEST(ScaleBias, RandomErrorsAverageOut) {
  const auto gt = winding_path(3000, 1.0);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);  // 1 % of every step, each direction
  std::vector<Pose> est{gt.front()};
  for (std::size_t i = 1; i < gt.size(); ++i) {
    Pose motion = gt[i - 1].inverse() * gt[i];
    motion.translation() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    est.push_back(est.back() * motion);
  }
  const ScaleBias bias = compute_scale_bias(gt, est);
  // Each sum holds 3000 errors of sigma 0.01 m: sigma 0.55 m over 3000 m,
  // 0.018 %; the bound is 3.3 sigma.
  EXPECT_LT(std::abs(bias.forward_percent), 0.06);
  EXPECT_LT(std::abs(bias.lateral_percent), 0.06);
  EXPECT_LT(std::abs(bias.vertical_percent), 0.06);
  // The same errors are about 0.5 % of a 10-frame window (sqrt(30) * 0.01 m over 10 m).
  EXPECT_GT(compute_rpe(gt, est, 10).trans.mean, 0.04);
}

TEST(ScaleBias, StandingStillAndUnknownAxes) {
  const std::vector<Pose> still(30, Pose::Identity());
  const ScaleBias none = compute_scale_bias(still, still);
  EXPECT_EQ(none.windows, 0u);
  EXPECT_TRUE(std::isnan(none.forward_percent));
  EXPECT_TRUE(std::isnan(none.lateral_percent));
  EXPECT_EQ(none.body_up, Eigen::Vector3d::Zero());
  // Standing windows are left out of a drive that stops halfway.
  auto gt = straight_path(21, 1.0);
  for (std::size_t i = 11; i < gt.size(); ++i) gt[i] = gt[10];
  const ScaleBias half = compute_scale_bias(gt, biased(gt, 0.002, 0.0, 0.0));
  EXPECT_EQ(half.windows, 1u);
  EXPECT_NEAR(half.forward_percent, 0.2, 1e-9);
  // Motion along body y fits neither convention: only the forward bias.
  std::vector<Pose> sideways;
  for (int i = 0; i < 21; ++i) sideways.push_back(make_pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, i, 0)));
  const ScaleBias side = compute_scale_bias(sideways, sideways);
  EXPECT_NEAR(side.forward_percent, 0.0, 1e-12);
  EXPECT_TRUE(std::isnan(side.lateral_percent));
  EXPECT_TRUE(std::isnan(side.vertical_percent));
  EXPECT_THROW(compute_scale_bias(gt, gt, 0), std::invalid_argument);
  EXPECT_THROW(compute_scale_bias(gt, still), std::invalid_argument);
}

TEST(AteAxes, SplitsTheErrorAlongEachPosesOwnAxes) {
  // Every position moved by a fixed offset in its own pose's frame (LiDAR
  // axes: 0.1 m forward, 0.3 m left, 0.2 m up) along a path that turns and
  // pitches: unaligned, each axis gets its own share, in both conventions.
  const auto gt = winding_path(800, 1.0);
  std::vector<Pose> est = gt;
  for (auto& T : est) T.translation() -= T.linear() * Eigen::Vector3d(0.1, 0.3, 0.2);
  for (const auto& [g, e] : {std::pair{gt, est}, std::pair{in_camera_frame(gt), in_camera_frame(est)}}) {
    const AteMetrics ate = compute_ate(g, e, Alignment::kNone);
    const AteAxes axes = compute_ate_axes(g, e, ate, body_up_axis(g));
    EXPECT_NEAR(axes.sideways_m, 0.3, 1e-9);
    EXPECT_NEAR(axes.vertical_m, 0.2, 1e-9);
    EXPECT_NEAR(axes.forward_m, 0.1, 1e-9);
  }
  // Aligned, the three squared add up to the ATE's squared RMSE.
  const auto drifting = biased(gt, -0.001, 0.0005, 0.002);
  const TrajectoryEvaluation ev = evaluate_trajectories(gt, drifting);
  const AteAxes& a = ev.ate_axes;
  EXPECT_NEAR(a.sideways_m * a.sideways_m + a.vertical_m * a.vertical_m + a.forward_m * a.forward_m,
              ev.ate.aligned.rmse * ev.ate.aligned.rmse, 1e-9);
  EXPECT_GT(a.vertical_m, a.sideways_m);  // the climb (0.2 %) is the largest drift
  // Motion along body y fits neither convention.
  std::vector<Pose> sideways;
  for (int i = 0; i < 21; ++i) sideways.push_back(make_pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, i, 0)));
  const AteAxes none = compute_ate_axes(sideways, sideways, compute_ate(sideways, sideways), body_up_axis(sideways));
  EXPECT_TRUE(std::isnan(none.vertical_m));
}

TEST(EvaluateTrajectories, IdenticalTrajectoriesAreZeroEverywhere) {
  const auto gt = winding_path(1500, 0.9);
  const auto ev = evaluate_trajectories(gt, gt);
  EXPECT_TRUE(ev.warnings.empty());
  EXPECT_EQ(ev.evaluated_poses, 1500u);
  EXPECT_NEAR(ev.gt_length_m, 1499 * 0.9, 1e-6);
  ASSERT_GT(ev.kitti.segments, 0u);
  EXPECT_NEAR(ev.kitti.t_err_percent, 0.0, 1e-9);
  EXPECT_NEAR(ev.kitti.r_err_deg_per_100m, 0.0, 1e-5);
  EXPECT_NEAR(ev.ate.aligned.rmse, 0.0, 1e-9);
  EXPECT_NEAR(ev.ate.unaligned.rmse, 0.0, 1e-12);
  EXPECT_NEAR(ev.rpe.trans_rmse_m, 0.0, 1e-9);
  EXPECT_NEAR(ev.rpe.rot_rmse_deg, 0.0, 1e-5);
  EXPECT_EQ(ev.bias.windows, 149u);
  EXPECT_NEAR(ev.bias.forward_percent, 0.0, 1e-9);
  EXPECT_NEAR(ev.bias.lateral_percent, 0.0, 1e-9);
  EXPECT_NEAR(ev.bias.vertical_percent, 0.0, 1e-9);
}

TEST(EvaluateTrajectories, ShorterEstimateUsesCommonPrefixWithWarning) {
  const auto gt = winding_path(1500, 0.9);
  std::vector<Pose> est;
  for (const auto& T : gt) {
    Pose noisy = T;
    noisy.translation() *= 1.02;
    est.push_back(noisy);
  }
  const std::vector<Pose> est_short(est.begin(), est.begin() + 1200);
  const auto ev = evaluate_trajectories(gt, est_short);
  EXPECT_EQ(ev.gt_poses, 1500u);
  EXPECT_EQ(ev.est_poses, 1200u);
  EXPECT_EQ(ev.evaluated_poses, 1200u);
  ASSERT_EQ(ev.warnings.size(), 1u);
  EXPECT_NE(ev.warnings[0].find("first 1200 poses"), std::string::npos) << ev.warnings[0];

  const std::vector<Pose> gt_prefix(gt.begin(), gt.begin() + 1200);
  const auto expected = evaluate_trajectories(gt_prefix, est_short);
  EXPECT_DOUBLE_EQ(ev.kitti.t_err_percent, expected.kitti.t_err_percent);
  EXPECT_DOUBLE_EQ(ev.ate.aligned.rmse, expected.ate.aligned.rmse);
  EXPECT_DOUBLE_EQ(ev.rpe.trans_rmse_m, expected.rpe.trans_rmse_m);
  EXPECT_EQ(ev.ate.aligned_errors.size(), 1200u);

  // A longer estimate is cut the same way.
  const auto longer = evaluate_trajectories(gt_prefix, est);
  EXPECT_EQ(longer.evaluated_poses, 1200u);
  EXPECT_EQ(longer.warnings.size(), 1u);
}

TEST(EvaluateTrajectories, NoOverlapIsAnError) {
  const auto gt = winding_path(10, 1.0);
  EXPECT_THROW(evaluate_trajectories(gt, {}), std::invalid_argument);
  EXPECT_THROW(evaluate_trajectories({}, gt), std::invalid_argument);
}

TEST(EvaluateTrajectories, ShortPathWarnsAboutKitti) {
  const auto gt = winding_path(30, 1.0);
  const auto ev = evaluate_trajectories(gt, gt);
  EXPECT_EQ(ev.kitti.segments, 0u);
  ASSERT_EQ(ev.warnings.size(), 1u);
  EXPECT_NE(ev.warnings[0].find("shorter than the shortest KITTI segment"), std::string::npos);
  EXPECT_NEAR(ev.ate.aligned.rmse, 0.0, 1e-9);
}

TEST(EvaluateTrajectories, Sim3OptionReachesAte) {
  const auto gt = winding_path(300, 1.0);
  std::vector<Pose> est = gt;
  for (auto& T : est) T.translation() *= 0.8;
  EvaluationOptions options;
  options.alignment = Alignment::kSim3;
  const auto ev = evaluate_trajectories(gt, est, options);
  EXPECT_EQ(ev.ate.alignment, Alignment::kSim3);
  EXPECT_NEAR(ev.ate.transform.scale, 1.25, 1e-9);
  EXPECT_LT(ev.ate.aligned.rmse, 1e-8);
  // KITTI and RPE are computed on the unaligned estimate: the scale error stays
  // visible (every 1 m step is 0.2 m short; KITTI sees 20 % of the chord, which
  // is shorter than the curved segment).
  EXPECT_NEAR(ev.rpe.trans_rmse_m, 0.2, 1e-9);
  EXPECT_GT(ev.kitti.t_err_percent, 10.0);
  EXPECT_LT(ev.kitti.t_err_percent, 20.0 + 1e-9);
}

}  // namespace
}  // namespace saloam
