// The live view of a run in progress (`--serve`): the map kept a piece every
// few metres and thinned on a long run, the poses a page lacks and all of
// them after loop closure, the newest scan, and the server's routes.

#include <gtest/gtest.h>

#include <cstring>
#include <set>
#include <tuple>

#include <nlohmann/json.hpp>

#include "saloam/core/error.hpp"
#include "saloam/viewer/live_view.hpp"
#include "saloam/viewer/point_encoding.hpp"
#include "saloam/viewer/viewer_server.hpp"
#include "viewer/viewer_fixture.hpp"

// After Eigen: httplib.h includes <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

namespace saloam {
namespace {

Pose at_x(double x) {
  Pose pose = Pose::Identity();
  pose.translation().x() = x;
  return pose;
}

std::uint32_t u32_at(const std::string& bytes, std::size_t offset) {
  std::uint32_t value = 0;
  std::memcpy(&value, bytes.data() + offset, 4);  // little-endian, as the machine
  return value;
}

struct Piece {
  std::uint32_t frame = 0;
  std::string points;
};

/// LiveView::map_chunks() as the page reads it.
std::vector<Piece> pieces_of(const std::string& bytes) {
  std::vector<Piece> pieces;
  for (std::size_t offset = 0; offset + 8 <= bytes.size();) {
    const std::uint32_t frame = u32_at(bytes, offset), n = u32_at(bytes, offset + 4);
    offset += 8;
    EXPECT_LE(offset + 7 * n, bytes.size());
    pieces.push_back({frame, bytes.substr(offset, 7 * n)});
    offset += 7 * n;
  }
  return pieces;
}


TEST(LiveView, KeepsAPieceOfTheMapEveryFewMetres) {
  LiveViewOptions options;
  options.chunk_spacing = 2.0;
  options.points_per_chunk = 500;
  LiveView view("seq", "slam", options);
  const LabelledCloud scan = testing::fake_scan(2000);
  for (int f = 0; f <= 20; ++f) view.add_frame(at_x(0.5 * f), scan);  // 10 m

  const std::vector<Piece> pieces = pieces_of(view.map_chunks(0));
  ASSERT_EQ(pieces.size(), 6U);
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    EXPECT_EQ(pieces[k].frame, 4 * k);  // every 2 m
    EXPECT_EQ(pieces[k].points.size(), 7U * 500U);  // every fourth point
    EXPECT_EQ(pieces[k].points.substr(0, 6), encode_scan(scan).substr(0, 6));  // the first one's xyz
  }
  EXPECT_EQ(view.chunks(), 6U);
  EXPECT_EQ(view.map_points(), 3000U);
  const std::vector<Piece> last = pieces_of(view.map_chunks(4));
  ASSERT_EQ(last.size(), 2U);
  EXPECT_EQ(last[0].frame, 16U);
  EXPECT_TRUE(view.map_chunks(6).empty());
}

TEST(LiveView, ALongRunThinsItsMap) {
  LiveViewOptions options;
  options.chunk_spacing = 1.0;
  options.points_per_chunk = 500;
  options.max_map_points = 1000;
  LiveView view("seq", "odom", options);
  const LabelledCloud scan = testing::fake_scan(2000);
  for (int f = 0; f <= 20; ++f) view.add_frame(at_x(f), scan);
  // Pieces at 0 and 1 m (1000 points: every 2 m on), 3 and 5 m (2000: every 4 m), 9, 13, 17 m.
  std::vector<std::uint32_t> frames;
  for (const Piece& piece : pieces_of(view.map_chunks(0))) frames.push_back(piece.frame);
  EXPECT_EQ(frames, (std::vector<std::uint32_t>{0, 1, 3, 5, 9, 13, 17}));
  EXPECT_EQ(nlohmann::json::parse(view.state_json(0, 0))["chunk_spacing"], 4.0);
}

TEST(LiveView, GivesThePosesAPageLacksAndAllOfThemAfterLoopClosure) {
  LiveView view("seq", "slam");
  const LabelledCloud scan = testing::fake_scan(100);
  for (int f = 0; f < 5; ++f) view.add_frame(at_x(f), scan);

  auto state = nlohmann::json::parse(view.state_json(0, 0));
  EXPECT_EQ(state["status"], "running");
  EXPECT_EQ(state["frames"], 5);
  EXPECT_EQ(state["first"], 0);
  std::vector<float> poses = testing::base64_floats(state["poses"]);
  ASSERT_EQ(poses.size(), 60U);
  EXPECT_EQ(poses[12 * 3 + 3], 3.0F);  // x of frame 3 ([R|t] rows)
  EXPECT_EQ(poses[12 * 3 + 0], 1.0F);
  state = nlohmann::json::parse(view.state_json(0, 3));
  EXPECT_EQ(state["first"], 3);
  EXPECT_EQ(testing::base64_floats(state["poses"]).size(), 24U);

  // Loop closure moves every frame: a page of the old revision gets them all.
  std::vector<Pose> moved;
  for (int f = 0; f < 5; ++f) moved.push_back(at_x(f + 0.25));
  view.replace_poses(moved);
  view.add_loop(4, 0);
  state = nlohmann::json::parse(view.state_json(0, 5));
  EXPECT_EQ(state["revision"], 1);
  EXPECT_EQ(state["first"], 0);
  poses = testing::base64_floats(state["poses"]);
  ASSERT_EQ(poses.size(), 60U);
  EXPECT_EQ(poses[12 * 4 + 3], 4.25F);
  EXPECT_EQ(state["loops"], nlohmann::json::parse("[[4, 0]]"));
  state = nlohmann::json::parse(view.state_json(1, 5));
  EXPECT_EQ(state["first"], 5);
  EXPECT_TRUE(testing::base64_floats(state["poses"]).empty());
  // More frames than the view holds: from its end.
  EXPECT_EQ(nlohmann::json::parse(view.state_json(1, 99))["first"], 5);

  EXPECT_THROW(view.replace_poses(std::vector<Pose>(4, Pose::Identity())), std::invalid_argument);
  view.finish(LiveRunStatus::kInterrupted);
  EXPECT_EQ(nlohmann::json::parse(view.state_json(1, 5))["status"], "interrupted");
}

TEST(LiveView, TheNewestScanIsNamedByItsFrameWithinItsBudget) {
  LiveViewOptions options;
  options.scan_points = 700;
  LiveView view("seq", "slam", options);
  EXPECT_TRUE(view.latest_scan().empty());
  const LabelledCloud scan = testing::fake_scan(2000);
  for (int f = 0; f < 3; ++f) view.add_frame(at_x(f), scan);
  const std::string latest = view.latest_scan();
  ASSERT_GE(latest.size(), 4U);
  EXPECT_EQ(u32_at(latest, 0), 2U);
  const std::size_t points = (latest.size() - 4) / 7;
  EXPECT_EQ((latest.size() - 4) % 7, 0U);
  EXPECT_LE(points, 700U);
  EXPECT_GE(points, 600U);  // every third point of 2000
}

TEST(LiveView, ABackgroundMapIsSentOnceWithItsQuantisation) {
  LiveView view("seq", "localize");
  const LabelledCloud map = testing::fake_street(5000);
  view.set_background(map);
  const MapQuantization q = map_quantization(map);
  EXPECT_EQ(view.background(), encode_map(map, q));
  const auto background = nlohmann::json::parse(view.state_json(0, 0))["background"];
  EXPECT_EQ(background["points"], 5000);
  EXPECT_EQ(background["scale"], q.scale);
  EXPECT_EQ(background["origin"][0], q.origin.x());
}

TEST(LiveView, TheServerAnswersThePageItsStateItsMapAndItsScan) {
  auto view = std::make_shared<LiveView>("seq", "slam");
  const LabelledCloud scan = testing::fake_scan(2000);
  for (int f = 0; f < 10; ++f) view->add_frame(at_x(f), scan);
  ViewerServer server(view);
  const int port = server.start("127.0.0.1", 0);

  // A second server on the port is refused (not given half the connections).
  ViewerServer second(view);
  EXPECT_THROW(second.start("127.0.0.1", port), InputError);
  EXPECT_FALSE(second.running());

  httplib::Client client("127.0.0.1", port);
  const auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<title>saloam live</title>"), std::string::npos);
  EXPECT_EQ(testing::page_data(page->body)["poll_ms"], 500);
  const auto state = client.Get("/live.json?revision=0&frames=4");
  ASSERT_TRUE(state);
  EXPECT_EQ(state->body, view->state_json(0, 4));
  const auto map = client.Get("/live/map?from=1");
  ASSERT_TRUE(map);
  EXPECT_EQ(map->body, view->map_chunks(1));
  EXPECT_FALSE(map->body.empty());
  const auto newest = client.Get("/live/scan");
  ASSERT_TRUE(newest);
  EXPECT_EQ(newest->body, view->latest_scan());
  for (const char* bad : {"/live.json?frames=x", "/live.json?revision=-1", "/live/map?from=1e3"}) {
    const auto answer = client.Get(bad);
    ASSERT_TRUE(answer);
    EXPECT_EQ(answer->status, 400) << bad;
  }
  const auto none = client.Get("/live/background");
  ASSERT_TRUE(none);
  EXPECT_TRUE(none->body.empty());
  EXPECT_TRUE(nlohmann::json::parse(view->state_json(0, 0))["background"].is_null());
  const auto rebound = client.Get("/live.json", {{"Host", "attacker.example:" + std::to_string(port)}});
  ASSERT_TRUE(rebound);
  EXPECT_EQ(rebound->status, 403);
}

}  // namespace
}  // namespace saloam
