// The one place search (slam/place_search.hpp) over a keyframe set of its
// own: ranking, one per place, the proximity proposal, thinning near a
// position, the submap's keyframes, and the hypothesis that later fixes
// confirm.

#include <cmath>

#include <gtest/gtest.h>

#include "saloam/core/lie.hpp"
#include "saloam/slam/place_search.hpp"

namespace saloam {
namespace {

/// Keyframes on the x axis at the given positions [m], one session unless
/// given, with one feature point each (at x = its index, sensor frame).
class LineOfKeyframes final : public KeyframeSet {
 public:
  explicit LineOfKeyframes(std::vector<double> x, std::vector<std::uint32_t> sessions = {})
      : x_(std::move(x)), sessions_(std::move(sessions)), places_(x_.size()) {
    if (sessions_.empty()) sessions_.assign(x_.size(), 0);
  }
  [[nodiscard]] std::size_t size() const override { return x_.size(); }
  [[nodiscard]] Pose pose(std::size_t k) const override {
    Pose p = Pose::Identity();
    p.translation().x() = x_[k];
    return p;
  }
  [[nodiscard]] std::uint32_t session(std::size_t k) const override { return sessions_[k]; }
  [[nodiscard]] bool in_frame(std::size_t k) const override { return sessions_[k] != kUnlinked; }
  [[nodiscard]] const PlaceDescriptor& place(std::size_t k) const override { return places_[k]; }
  [[nodiscard]] Eigen::Matrix3d level(std::size_t) const override { return Eigen::Matrix3d::Identity(); }
  [[nodiscard]] ScanFeatures scan_features(std::size_t k) const override {
    ++features_read;
    ScanFeatures f;
    f.planars.push_back(Eigen::Vector3d(static_cast<double>(k), 0, 0), 0, 0.0F);
    return f;
  }
  [[nodiscard]] std::vector<std::size_t> near(const Eigen::Vector3d& position, double radius) const override {
    std::vector<std::size_t> found;
    for (std::size_t k = 0; k < x_.size(); ++k) {
      if ((pose(k).translation() - position).norm() <= radius) found.push_back(k);
    }
    return found;
  }

  static constexpr std::uint32_t kUnlinked = 9;
  mutable int features_read = 0;

 private:
  std::vector<double> x_;
  std::vector<std::uint32_t> sessions_;
  std::vector<PlaceDescriptor> places_;
};

ScoredCandidates scored(std::vector<std::size_t> keyframes, std::vector<double> scores) {
  ScoredCandidates s;
  s.keyframes = std::move(keyframes);
  for (const double score : scores) {
    PlaceMatch match;
    match.score = score;
    s.matches.push_back(match);
  }
  return s;
}

std::vector<std::size_t> keyframes_of(const std::vector<PlaceProposal>& proposals) {
  std::vector<std::size_t> k;
  for (const PlaceProposal& p : proposals) k.push_back(p.keyframe);
  return k;
}

TEST(PlaceSearch, RanksAboveTheThresholdBestFirstOlderOnTies) {
  const LineOfKeyframes set({0, 100, 200, 300, 400});
  const PlaceSearchOptions options{0.5, 3, 0.0};
  const auto ranked = rank_places(set, scored({0, 1, 2, 3, 4}, {0.4, 0.7, 0.9, 0.7, 0.6}), options);
  EXPECT_EQ(keyframes_of(ranked), (std::vector<std::size_t>{2, 1, 3}));  // 0.4 below; 0.6 beyond N_loop
}

TEST(PlaceSearch, KeepsOnePerPlaceWhenAskedTo) {
  const LineOfKeyframes set({0, 2, 4, 50});
  const auto candidates = scored({0, 1, 2, 3}, {0.9, 0.8, 0.7, 0.6});
  EXPECT_EQ(keyframes_of(rank_places(set, candidates, {0.5, 3, 5.0})), (std::vector<std::size_t>{0, 3}));
  EXPECT_EQ(keyframes_of(rank_places(set, candidates, {0.5, 3, 0.0})), (std::vector<std::size_t>{0, 1, 2}));
}

// The live SLAM's queries from the side (loop.lateral_query_offset): with
// every keyframe its own place, yet a keyframe that two queries propose is
// verified once, with its best proposal; the best N_loop over all queries.
TEST(PlaceSearch, MergesQueriesBestFirstEachKeyframeOnce) {
  const LineOfKeyframes set({0, 10, 20, 30});
  const PlaceSearchOptions options{0.5, 3, 0.0};
  std::vector<PlaceProposal> proposed = rank_places(set, scored({0, 1, 2}, {0.7, 0.6, 0.55}), options);
  for (const PlaceProposal& p : rank_places(set, scored({1, 3}, {0.8, 0.6}), options, 3.2)) proposed.push_back(p);
  const std::vector<PlaceProposal> merged = merge_proposals(set, proposed, options);
  ASSERT_EQ(keyframes_of(merged), (std::vector<std::size_t>{1, 0, 3}));  // 1 once; 3 ties with 1's 0.6, comes later
  EXPECT_DOUBLE_EQ(merged[0].query_offset, 3.2);
  EXPECT_DOUBLE_EQ(merged[1].query_offset, 0.0);
  EXPECT_DOUBLE_EQ(merged[2].query_offset, 3.2);
}

TEST(PlaceSearch, ProposesTheNearestCandidateOnceWhateverItsScore) {
  const LineOfKeyframes set({0, 10, 20});
  const auto candidates = scored({0, 1, 2}, {0.9, 0.1, 0.2});
  std::vector<PlaceProposal> proposals = rank_places(set, candidates, {0.5, 5, 0.0});
  add_nearest(proposals, set, candidates, Eigen::Vector3d(11, 0, 0), 5.0);
  ASSERT_EQ(keyframes_of(proposals), (std::vector<std::size_t>{0, 1}));
  EXPECT_TRUE(proposals[1].by_proximity);
  EXPECT_DOUBLE_EQ(proposals[1].match.score, 0.1);
  add_nearest(proposals, set, candidates, Eigen::Vector3d(11, 0, 0), 5.0);  // already proposed
  EXPECT_EQ(proposals.size(), 2U);
  add_nearest(proposals, set, candidates, Eigen::Vector3d(40, 0, 0), 5.0);  // none within the radius
  EXPECT_EQ(proposals.size(), 2U);
}

TEST(PlaceSearch, ThinsNearAPositionAndSkipsSessionsOutsideTheFrame) {
  const LineOfKeyframes set({0, 1, 3, 6, 7, 30}, {0, 0, 0, LineOfKeyframes::kUnlinked, 0, 0});
  EXPECT_EQ(thinned_near(set, Eigen::Vector3d::Zero(), 10.0, 2.5), (std::vector<std::size_t>{0, 2, 4}));
  EXPECT_EQ(all_keyframes(set).size(), 6U);
}

TEST(PlaceSearch, SubmapTakesTheProposalsSessionAndWhatTheCallerAdmits) {
  const LoopVerificationSettings settings = LoopVerificationSettings::from_config(SaloamConfig{});
  const LineOfKeyframes set({0, 1, 2, 3, 4, 5, 6}, {0, 0, 1, 1, 1, 1, 1});
  (void)submap_around(set, 4, 2, settings, set.size());  // keyframes 2..6, session 1
  EXPECT_EQ(set.features_read, 5);
  set.features_read = 0;
  (void)submap_around(set, 4, 2, settings, 6, [](std::size_t k) { return k != 3; });  // 2, 4, 5
  EXPECT_EQ(set.features_read, 3);
}

TEST(PlaceSearch, LateralGuessMovesTheQueryToItsSide) {
  PlaceProposal p;
  p.match.yaw = M_PI / 2;
  p.query_offset = 3.0;
  // T_keyframe<-query = yaw 90 deg; the sensor lies 3 m to the query's right.
  const Pose guess = p.lateral_guess();
  EXPECT_NEAR(guess.translation().x(), 3.0, 1e-12);
  EXPECT_NEAR(guess.translation().y(), 0.0, 1e-12);
  EXPECT_NEAR(rotation_angle(guess), M_PI / 2, 1e-12);
}

TEST(PlaceHypothesis, PredictsFromItsLinkAndCountsItsConfirmations) {
  Pose fit = Pose::Identity();
  fit.translation() = Eigen::Vector3d(100, 50, 0);
  Pose odometry = Pose::Identity();
  odometry.translation() = Eigen::Vector3d(10, 0, 0);
  PlaceHypothesis h = PlaceHypothesis::from_fit(fit, odometry, 12.0, 2);
  EXPECT_FALSE(h.confirmed());
  EXPECT_DOUBLE_EQ(h.last_fix, 12.0);
  Pose later = odometry;
  later.translation().x() += 5;
  EXPECT_TRUE(h.predict(later).translation().isApprox(Eigen::Vector3d(105, 50, 0)));
  Pose refit = fit;
  refit.translation().x() += 5.5;
  EXPECT_FALSE(h.confirm(refit, later, 17.0));
  EXPECT_TRUE(h.predict(later).translation().isApprox(refit.translation()));  // the link moved to the fix
  EXPECT_TRUE(h.last_pose.isApprox(refit));
  EXPECT_TRUE(h.confirm(refit, later, 22.0));
  EXPECT_TRUE(h.confirmed());
  EXPECT_TRUE(PlaceHypothesis::from_fit(fit, odometry, 0.0, 0).confirmed());
}

}  // namespace
}  // namespace saloam
