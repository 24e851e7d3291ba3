// Localisation in a saved map, on simulated passes through one world
// (SimulationOptions::passes) whose true relative pose is known: the map is
// made by the SLAM over the first pass, saved and read back; later passes
// (other start, time, moving objects, label noise; the opposite direction)
// are localised in it with no initial guess.

#include <cstdio>
#include <functional>
#include <limits>
#include <map>

#include <gtest/gtest.h>

#include "saloam/core/lie.hpp"
#include "saloam/eval/trajectory_metrics.hpp"
#include "saloam/maps/localizer.hpp"
#include "saloam/maps/slam_map.hpp"
#include "saloam/sim/simulator.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

// urban-loop (about 1.3 km, its first ~200 m driven again at the end), every
// second pose, 16 beams, noisy labels. Pass 0 (mapped): route poses 0:500.
// Pass 1: 300:end, starting inside the map, leaving it at 500, coming back
// over the route's start at the end. Pass 2: 80:460 in the opposite lane,
// backwards.
SimulationOptions pass_options(std::size_t pass, std::uint64_t seed) {
  SimulationOptions sim;
  sim.preset = "urban-loop";
  sim.passes = {RoutePass{0, 500, false}, RoutePass{300, std::numeric_limits<std::size_t>::max(), false},
                RoutePass{80, 460, true}};
  sim.pass = pass;
  sim.stride = 2;
  sim.beams = 16;
  sim.seed = seed;
  sim.labels = LabelMode::kNoisy;
  sim.show_progress = false;
  return sim;
}

struct Session {
  std::vector<LocalizedFrame> frames;
  std::vector<RelocalizationRecord> relocalizations;
  std::optional<double> first_placed;
  std::vector<Pose> truth;  ///< T_map<-sensor of every frame
};

// The map of pass 0 of world `seed`, saved and opened again; and the truth's
// alignment of the map (the map's own error taken out, as its ATE does).
struct TestMap {
  testing::TempDir dir{"saloam_localize_map"};
  std::unique_ptr<PriorMap> map;
  Pose map_origin;       ///< world pose of the map frame
  Pose alignment;        ///< map estimate -> truth
  double mapping_ate = 0;
};

const TestMap& test_map(std::uint64_t seed) {
  static std::map<std::uint64_t, std::unique_ptr<TestMap>> maps;
  auto& slot = maps[seed];
  if (slot) return *slot;
  slot = std::make_unique<TestMap>();
  const SimulatedSequence sequence(pass_options(0, seed));
  SaloamConfig config;
  SlamSystem slam(config, std::nullopt);
  for (std::size_t k = 0; k < sequence.size(); ++k) slam.process(sequence.render(k).cloud, sequence.times()[k]);
  write_slam_map(slot->dir / "map", slam, config, MapManifest{});
  slot->map = std::make_unique<PriorMap>(PriorMap::open(slot->dir / "map", 200));
  slot->map_origin = sequence.origin();
  // Truth of the map's keyframes (LiDAR frame of pass 0's first frame).
  const Pose tr = sequence.velo_to_cam();
  std::vector<Eigen::Vector3d> estimated, reference;
  for (const auto& kf : slot->map->saved().keyframes) {
    estimated.push_back(kf.pose.translation());
    reference.push_back((tr.inverse() * sequence.camera_poses()[kf.frame] * tr).translation());
  }
  const SimilarityTransform s = umeyama_alignment(estimated, reference, false);
  slot->alignment = Pose::Identity();
  slot->alignment.linear() = s.rotation;
  slot->alignment.translation() = s.translation;
  std::vector<Pose> truth, estimate;
  for (std::size_t k = 0; k < sequence.size(); ++k) truth.push_back(tr.inverse() * sequence.camera_poses()[k] * tr);
  slot->mapping_ate = compute_ate(truth, slam.optimized_poses()).aligned.rmse;
  return *slot;
}

Session localize(const TestMap& map, std::size_t pass, std::uint64_t world_seed,
                 std::size_t frames = std::numeric_limits<std::size_t>::max(),
                 const std::function<void(LocalizeConfig&)>& change = {}) {
  SimulationOptions sim = pass_options(pass, world_seed);
  sim.end_frame = frames;
  const SimulatedSequence sequence(sim);
  SaloamConfig config = map.map->saved().config;
  if (change) change(config.localize);
  Localizer localizer(config, *map.map, std::nullopt);
  Session s;
  const Pose tr = sequence.velo_to_cam();
  const Pose map_from_first = map.map_origin.inverse() * sequence.origin();
  for (std::size_t k = 0; k < sequence.size(); ++k) {
    localizer.process(sequence.render(k).cloud, sequence.times()[k]);
    s.truth.push_back(orthonormalized(map_from_first * tr.inverse() * sequence.camera_poses()[k] * tr));
  }
  s.frames = localizer.frames();
  s.relocalizations = localizer.relocalizations();
  s.first_placed = localizer.first_placed_at();
  return s;
}

bool agrees(const Pose& estimate, const Pose& truth) {
  const Pose d = truth.inverse() * estimate;
  return d.translation().norm() < 0.5 && rotation_angle(d) < 2.0 * M_PI / 180;
}

std::size_t false_relocalizations(const TestMap& map, const Session& s) {
  std::size_t n = 0;
  for (const auto& r : s.relocalizations)
    if ((r.outcome == "hypothesis" || r.outcome == "confirmed") && !agrees(map.alignment * r.pose, s.truth[r.frame])) ++n;
  return n;
}

// Confirmed relocalisations (a pose written) that are not the truth.
std::size_t false_confirmations(const TestMap& map, const Session& s) {
  std::size_t n = 0;
  for (const auto& r : s.relocalizations)
    if (r.outcome == "confirmed" && !agrees(map.alignment * r.pose, s.truth[r.frame])) ++n;
  return n;
}

TEST(Localize, RelocalisesWithoutPriorLeavesAndReentersTheMap) {
  const TestMap& map = test_map(5);
  const Session s = localize(map, 1, 5);
  ASSERT_TRUE(s.first_placed);
  EXPECT_LT(*s.first_placed, 50.0);
  EXPECT_EQ(false_relocalizations(map, s), 0u);
  std::vector<double> errors;
  std::size_t left = 0, back = 0, odometry = 0;
  bool left_once = false;
  for (const auto& f : s.frames) {
    if (f.status == LocalizationStatus::kLocalized) errors.push_back(((map.alignment * f.pose).translation() - s.truth[f.frame].translation()).norm());
    if (f.status == LocalizationStatus::kOdometry) ++odometry;
    if (f.event == "left the mapped area") ++left, left_once = true;
    if (left_once && f.status == LocalizationStatus::kLocalized && f.fitted) back = std::max<std::size_t>(back, 1);
  }
  const ErrorStats e = error_stats(errors);
  std::printf("placed after %.1f m; localized %zu frames: RMSE %.3f m, max %.3f m (mapping ATE %.3f m); %zu on the "
              "odometry; left %zu times; %zu relocalisation records\n",
              *s.first_placed, errors.size(), e.rmse, e.max, map.mapping_ate, odometry, left, s.relocalizations.size());
  EXPECT_LT(e.rmse, 0.3);
  EXPECT_GE(left, 1u) << "pass 1 leaves the mapped stretch";
  EXPECT_GT(odometry, 0u);
  EXPECT_EQ(back, 1u) << "pass 1 comes back over the mapped start";
  // The end of pass 1 drives the route's start again: it is in the map there.
  EXPECT_EQ(s.frames.back().status, LocalizationStatus::kLocalized);
}

TEST(Localize, RelocalisesDrivingTheOppositeWay) {
  const TestMap& map = test_map(5);
  const Session s = localize(map, 2, 5);
  ASSERT_TRUE(s.first_placed);
  EXPECT_EQ(false_relocalizations(map, s), 0u);
  std::size_t localized = 0;
  for (const auto& f : s.frames) {
    if (f.status != LocalizationStatus::kLocalized) continue;
    ++localized;
    EXPECT_LT(((map.alignment * f.pose).translation() - s.truth[f.frame].translation()).norm(), 1.0) << "frame " << f.frame;
  }
  std::printf("reverse: placed after %.1f m, %zu of %zu frames localized\n", *s.first_placed, localized, s.frames.size());
  EXPECT_GT(localized, s.frames.size() / 2);
}

TEST(Localize, QueriesFromTheSidePlaceTheOppositeLaneSooner) {
  // Scan Context compares scans taken from one spot; the reverse pass drives
  // 3.2 m beside the mapped lane. Described also from a lane width to either
  // side (localize.lateral_query_offset), the scan finds its place sooner.
  const TestMap& map = test_map(5);
  const Session from_sensor = localize(map, 2, 5, 60, [](LocalizeConfig& c) { c.lateral_query_offset = 0; });
  const Session from_sides = localize(map, 2, 5, 60);
  ASSERT_TRUE(from_sides.first_placed);
  EXPECT_EQ(false_confirmations(map, from_sides), 0u);
  EXPECT_LT(*from_sides.first_placed, from_sensor.first_placed.value_or(1e9));
  std::printf("seed 5 reverse: placed after %.1f m from the sensor's query only, %.1f m with queries from the side\n",
              from_sensor.first_placed.value_or(-1.0), *from_sides.first_placed);
}

TEST(Localize, RefusesTheReversePassTurnedAlongTheStreet) {
  // World seed 6, the reverse pass over 60 route poses (30 frames, about 65 m): its first
  // descriptor match fits it turned by 180 degrees in the mapped lane, metres
  // from the truth. Fits started from the poses that hypothesis predicts
  // slide along the straight street with the wrongly predicted motion and
  // pass the acceptance test; started from the last fix's pose they land
  // elsewhere, which refutes it. The run is placed later, where it is.
  // (The uniqueness test of a place found with no prior, which refuses that
  // hypothesis before any confirmation, is off here: this tests the other.
  // So are the queries from the side, which find the right place first.)
  const TestMap& map = test_map(6);
  const Session s = localize(map, 2, 6, 60, [](LocalizeConfig& c) {
    c.max_runner_up_ratio = kInf;
    c.lateral_query_offset = 0;
  });
  std::size_t wrong_hypotheses = 0, refuted_by_motion = 0;
  for (const auto& r : s.relocalizations) {
    if (r.outcome == "hypothesis" && !agrees(map.alignment * r.pose, s.truth[r.frame])) ++wrong_hypotheses;
    if (r.outcome == "refuted" && r.verification.reason.starts_with("the fit follows the predicted motion")) ++refuted_by_motion;
  }
  EXPECT_GE(wrong_hypotheses, 1u) << "the set-up no longer makes the wrong hypothesis this test is about";
  EXPECT_GE(refuted_by_motion, 1u);
  EXPECT_EQ(false_confirmations(map, s), 0u);
  ASSERT_TRUE(s.first_placed);
  EXPECT_LT(*s.first_placed, 50.0);
  std::size_t localized = 0;
  for (const auto& f : s.frames) {
    if (f.status != LocalizationStatus::kLocalized) continue;
    ++localized;
    EXPECT_LT(((map.alignment * f.pose).translation() - s.truth[f.frame].translation()).norm(), 1.0) << "frame " << f.frame;
  }
  std::printf("seed 6 reverse: %zu wrong hypotheses, %zu refuted as following the prediction; placed after %.1f m, "
              "%zu of %zu frames localized\n", wrong_hypotheses, refuted_by_motion, *s.first_placed, localized,
              s.frames.size());
  EXPECT_GT(localized, s.frames.size() / 2);
}

TEST(Localize, RefusesAPlaceItCannotTellAlongTheStreet) {
  // The same reverse pass with no confirming fixes: the candidate's own fit
  // decides. Without the uniqueness test a wrong place along the straight
  // street passes the acceptance test and is believed (the set-up this test
  // needs); with it, every such fit has a distinct solution along the street
  // nearly as good and is refused, and the run is placed where it is.
  // (Queries from the sensor only: those from the side find the right place
  // before the wrong one arises.)
  const TestMap& map = test_map(6);
  const auto no_confirmations = [](double ratio) {
    return [ratio](LocalizeConfig& c) {
      c.confirmations = 0;
      c.max_runner_up_ratio = ratio;
      c.lateral_query_offset = 0;
    };
  };
  const Session without = localize(map, 2, 6, 60, no_confirmations(kInf));
  EXPECT_GE(false_confirmations(map, without), 1u) << "the set-up no longer makes the wrong place this test is about";
  const Session s = localize(map, 2, 6, 60, no_confirmations(LocalizeConfig{}.max_runner_up_ratio));
  std::size_t ambiguous = 0;
  for (const auto& r : s.relocalizations) ambiguous += r.verification.reason.starts_with("ambiguous");
  EXPECT_GE(ambiguous, 1u);
  EXPECT_EQ(false_confirmations(map, s), 0u);
  ASSERT_TRUE(s.first_placed);
  EXPECT_LT(*s.first_placed, 50.0);
  std::printf("seed 6 reverse, no confirmations: %zu false places believed without the uniqueness test, %zu with it "
              "(%zu fits refused as ambiguous); placed after %.1f m\n", false_confirmations(map, without),
              false_confirmations(map, s), ambiguous, *s.first_placed);
}

TEST(Localize, RefusesAPlaceOfAnotherWorld) {
  // Another route (figure-eight) through another world (seed 6): nothing in
  // the map is the place, so no frame may be placed. (The same route with
  // another seed is not another place: its roads, curbs and hills follow the
  // route and stay where they were, only buildings and trees change, and the
  // localisation finds the road where it is.)
  const TestMap& map = test_map(5);
  SimulationOptions sim = pass_options(1, 6);
  sim.preset = "figure-eight";
  sim.passes.clear();
  sim.pass = 0;
  sim.end_frame = 400;  // about 400 m of another world
  const SimulatedSequence sequence(sim);
  Localizer localizer(map.map->saved().config, *map.map, std::nullopt);
  for (std::size_t k = 0; k < sequence.size(); ++k) {
    const LocalizedFrame& f = localizer.process(sequence.render(k).cloud, sequence.times()[k]);
    EXPECT_EQ(f.status, LocalizationStatus::kUnplaced) << "frame " << k;
  }
  std::size_t verified = 0;
  for (const auto& r : localizer.relocalizations()) {
    EXPECT_NE(r.outcome, "confirmed");
    verified += r.keyframe.has_value();
  }
  std::printf("another world: %zu candidates verified, none confirmed\n", verified);
}

}  // namespace
}  // namespace saloam
