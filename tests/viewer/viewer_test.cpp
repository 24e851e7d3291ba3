// The viewer page: its data, the point budgets, the encodings, bad input,
// the local server, and a saved map's sessions.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <regex>
#include <thread>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fmt/format.h>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/maps/map_format.hpp"
#include "saloam/place/scan_context.hpp"
#include "saloam/viewer/point_encoding.hpp"
#include "saloam/viewer/viewer_page.hpp"
#include "saloam/viewer/viewer_server.hpp"
#include "testing/test_support.hpp"
#include "viewer/viewer_fixture.hpp"

// After Eigen: httplib.h includes <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

std::size_t decoded_size(const std::string& base64_text) {
  const std::size_t padding = base64_text.ends_with("==") ? 2 : base64_text.ends_with('=') ? 1 : 0;
  return base64_text.size() / 4 * 3 - padding;
}

TEST(Viewer, Base64MatchesRfc4648) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\xfe\x00", 3)), "//4A");
}

TEST(Viewer, PageIsSelfContainedAndHoldsTheRun) {
  TempDir tmp;
  const auto run = testing::write_fake_run(tmp.path(), 5000);
  const fs::path page = tmp / "view.html";
  const ViewerPageStats stats = write_viewer_page(run.run_dir, page);
  const std::string html = testing::read_text(page);
  EXPECT_EQ(stats.bytes, html.size());
  EXPECT_GT(html.size(), 800'000U) << "three.js is inlined";
  EXPECT_NE(html.find("OrbitControls"), std::string::npos);
  // Nothing is fetched from elsewhere: no script, style or image source, no URL to load.
  EXPECT_FALSE(std::regex_search(html, std::regex(R"(<(script|link|img)[^>]*(src|href)\s*=)", std::regex::icase)));
  EXPECT_EQ(html.find("fetch('http"), std::string::npos);

  const auto data = testing::page_data(html);
  ASSERT_FALSE(data.is_null());
  EXPECT_EQ(data["source"], "embedded");
  EXPECT_EQ(data["map"]["count"], 5000U);
  EXPECT_EQ(data["map"]["total"], 5000U);
  EXPECT_EQ(decoded_size(data["map"]["data"]), 7U * 5000U);
  EXPECT_EQ(data["frames"], run.frames);
  EXPECT_EQ(decoded_size(data["poses"]), 12U * 4U * run.frames);
  EXPECT_EQ(data["loops"].size(), run.loops_accepted);
  EXPECT_EQ(data["loops_verified"], run.loops_verified);
  ASSERT_EQ(data["trajectories"].size(), 3U);
  EXPECT_EQ(data["trajectories"][0]["name"], "ground truth");
  EXPECT_EQ(data["trajectories"][1]["name"], "odometry");
  EXPECT_EQ(data["trajectories"][2]["name"], "loop closed");
  for (const auto& t : data["trajectories"]) EXPECT_EQ(decoded_size(t["positions"]), 12U * run.frames);
  EXPECT_EQ(data["scans"]["source"], "embedded");
  EXPECT_EQ(data["scans"]["frames"].size(), stats.scans);
  EXPECT_EQ(stats.map_points, 5000U);
  EXPECT_EQ(stats.loops, run.loops_accepted);
  EXPECT_TRUE(stats.ground_truth);

  // One class run per class: road, building, vegetation, car.
  std::size_t ranged = 0;
  for (const auto& r : data["map"]["ranges"]) ranged += r[2].get<std::size_t>();
  EXPECT_EQ(ranged, 5000U);
  EXPECT_EQ(data["map"]["ranges"].size(), 4U);
}

TEST(Viewer, MapAndScansKeepToTheirBudgets) {
  TempDir tmp;
  const auto run = testing::write_fake_run(tmp.path(), 20'000, 40, 3000);
  ViewerOptions options;
  options.max_map_points = 3000;
  options.points_per_scan = 500;
  options.max_scan_points = 5000;
  ViewerPageStats stats;
  const std::string html =
      viewer_page(load_viewer_scene(run.run_dir, options), options, ViewerDataSource::kEmbedded, &stats);
  const auto data = testing::page_data(html);
  EXPECT_EQ(data["map"]["count"], 3000U);
  EXPECT_EQ(data["map"]["total"], 20'000U);
  EXPECT_EQ(decoded_size(data["map"]["data"]), 7U * 3000U);
  EXPECT_EQ(stats.scans, 10U);  // 5000 / 500, spread over the 40 frames: every 4th
  EXPECT_EQ(data["scans"]["frames"][1], 4U);
  EXPECT_LE(stats.scan_points, options.max_scan_points);
  for (const auto& scan : data["scans"]["data"]) EXPECT_EQ(decoded_size(scan), 7U * 500U);
}

TEST(Viewer, DecimationIsAnEvenSubsetSortedByClass) {
  const LabelledCloud map = testing::fake_street(10'000);
  const LabelledCloud small = decimate_cloud(map, 1000);
  ASSERT_EQ(small.size(), 1000U);
  EXPECT_TRUE(std::is_sorted(small.label.begin(), small.label.end()));
  std::map<std::uint16_t, int> per_class;
  for (const auto label : small.label) ++per_class[label];
  for (const auto& [label, count] : per_class) EXPECT_NEAR(count, 250, 60) << class_name(label);
  EXPECT_EQ(decimate_cloud(map, 20'000).size(), map.size());
}

TEST(Viewer, EncodingsRoundTripWithinTheirStep) {
  LabelledCloud cloud = testing::fake_scan(100);
  cloud.push_back(Eigen::Vector3f(500, 0, 0), 0, cls::kPole);  // beyond the scan encoding's range: left out
  const std::string scan = encode_scan(cloud);
  ASSERT_EQ(scan.size(), 7U * 100U);
  std::int16_t x0 = 0;
  std::memcpy(&x0, scan.data(), 2);
  EXPECT_NEAR(x0 * kScanScale, cloud.points[0].x(), kScanScale);
  EXPECT_EQ(static_cast<std::uint8_t>(scan[600]), class_index(cls::kRoad));
  EXPECT_EQ(class_name(semantic_kitti_classes()[class_index(cls::kBuilding)].id), "building");
  EXPECT_EQ(class_index(12345), unknown_class_index());

  const MapQuantization q = map_quantization(cloud);
  const std::string map = encode_map(cloud, q);
  std::uint16_t last_x = 0;
  std::memcpy(&last_x, map.data() + 6 * 100, 2);
  EXPECT_NEAR(q.origin.x() + last_x * q.scale, 500.0, q.scale);
}

TEST(Viewer, BadInputGivesClearErrors) {
  TempDir tmp;
  EXPECT_NE(testing::input_error_of([&] { load_viewer_scene(tmp / "nowhere"); }).find("nowhere: run folder not found"),
            std::string::npos);
  const auto run = testing::write_fake_run(tmp.path(), 100);
  fs::remove(run.run_dir / "map.ply");
  const std::string missing_map = testing::input_error_of([&] { load_viewer_scene(run.run_dir); });
  EXPECT_NE(missing_map.find("map.ply: not found"), std::string::npos) << missing_map;
  EXPECT_NE(missing_map.find("--no-map"), std::string::npos) << missing_map;

  const auto run2 = testing::write_fake_run(tmp / "b", 100);
  std::ofstream(run2.run_dir / "loops.csv") << "query_frame,match_frame,accepted\n3,x,1\n";
  EXPECT_NE(testing::input_error_of([&] {
              load_viewer_scene(run2.run_dir);
            }).find("loops.csv: line 2: 'x' is not a frame index"),
            std::string::npos);
  std::ofstream(run2.run_dir / "loops.csv") << "query_frame,match_frame,accepted\n300,1,1\n";
  EXPECT_NE(testing::input_error_of([&] { load_viewer_scene(run2.run_dir); }).find("beyond the 40 poses"),
            std::string::npos);

  const auto run3 = testing::write_fake_run(tmp / "c", 100);
  ViewerOptions options;
  options.sequence = tmp / "no_sequence";
  EXPECT_NE(
      testing::input_error_of([&] { load_viewer_scene(run3.run_dir, options); }).find("sequence folder not found"),
      std::string::npos);
}

TEST(Viewer, RunWithoutSequenceHasNoGroundTruthAndNoScans) {
  TempDir tmp;
  const auto run = testing::write_fake_run(tmp.path(), 100);
  fs::remove(run.run_dir / "summary.json");
  ViewerPageStats stats;
  const ViewerScene scene = load_viewer_scene(run.run_dir);
  const auto data = testing::page_data(viewer_page(scene, {}, ViewerDataSource::kEmbedded, &stats));
  EXPECT_FALSE(stats.ground_truth);
  EXPECT_EQ(stats.scans, 0U);
  EXPECT_EQ(data["scans"]["source"], "none");
  EXPECT_EQ(data["trajectories"].size(), 2U);
}

TEST(Viewer, FramesFromMemoryGiveGroundTruthAndScansWithoutASequence) {
  TempDir tmp;
  const auto run = testing::write_fake_run(tmp.path(), 100, 40, 500);
  fs::remove(run.run_dir / "summary.json");
  ViewerOptions options;
  options.ground_truth = testing::straight_poses(run.frames, 2.5, 0.0);
  std::vector<std::size_t> rendered;
  options.scans = [&](std::size_t frame) {
    rendered.push_back(frame);
    return testing::fake_scan(500);
  };
  ViewerPageStats stats;
  const ViewerScene scene = load_viewer_scene(run.run_dir, options);
  const auto data = testing::page_data(viewer_page(scene, options, ViewerDataSource::kEmbedded, &stats));
  EXPECT_TRUE(stats.ground_truth);
  EXPECT_EQ(data["trajectories"].size(), 3U);
  EXPECT_GT(stats.scans, 0U);
  EXPECT_EQ(rendered.size(), stats.scans);  // only the embedded frames are asked for
  // A ground truth of another length is refused.
  options.ground_truth->pop_back();
  EXPECT_NE(testing::input_error_of([&] { load_viewer_scene(run.run_dir, options); }).find("ground-truth poses"),
            std::string::npos);
}

TEST(Viewer, ServerSendsThePageTheMapAndScansOnDemand) {
  TempDir tmp;
  const auto run = testing::write_fake_run(tmp.path(), 2000, 20, 1000);
  ViewerOptions options;
  options.points_per_scan = 600;
  ViewerServer server(load_viewer_scene(run.run_dir, options), options);
  const int port = server.start("127.0.0.1", 0);
  ASSERT_GT(port, 0);
  EXPECT_TRUE(server.running());
  EXPECT_THROW(server.start("127.0.0.1", 0), std::logic_error);

  httplib::Client client("127.0.0.1", port);
  const auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  const auto data = testing::page_data(page->body);
  EXPECT_EQ(data["source"], "server");
  EXPECT_EQ(data["scans"]["source"], "server");
  EXPECT_FALSE(data["map"].contains("data"));
  const auto map = client.Get("/map.bin");
  ASSERT_TRUE(map);
  EXPECT_EQ(map->body.size(), 7U * 2000U);
  const auto scan = client.Get("/scan/7");
  ASSERT_TRUE(scan);
  EXPECT_EQ(scan->status, 200);
  EXPECT_EQ(scan->body.size(), 7U * 600U);
  const auto beyond = client.Get("/scan/20");
  ASSERT_TRUE(beyond);
  EXPECT_EQ(beyond->status, 404);
  EXPECT_NE(beyond->body.find("scan 20: not available"), std::string::npos) << beyond->body;
  // No file name or absolute path in an error body (the log has them).
  EXPECT_EQ(beyond->body.find(tmp.path().string()), std::string::npos) << beyond->body;
  EXPECT_EQ(beyond->body.find('/'), std::string::npos) << beyond->body;
  const auto huge = client.Get("/scan/99999999999999999999999");
  ASSERT_TRUE(huge);
  EXPECT_EQ(huge->status, 404);
  EXPECT_LT(huge->body.size(), 100u) << huge->body;

  server.stop();
  EXPECT_FALSE(server.running());
  EXPECT_FALSE(client.Get("/"));  // nothing answers any more
  server.stop();  // again: nothing
}

// A server on a fake run, listening on 127.0.0.1 until the fixture ends.
struct ServingRun {
  TempDir tmp;
  std::unique_ptr<ViewerServer> server;
  int port = 0;

  ServingRun() {
    const auto run = testing::write_fake_run(tmp.path(), 500, 5, 200);
    const ViewerOptions options;
    server = std::make_unique<ViewerServer>(load_viewer_scene(run.run_dir, options), options);
    port = server->start("127.0.0.1", 0);
  }
};

TEST(Viewer, ServerAnswersOnlyToLoopbackHostNames) {
  // DNS rebinding: a page of evil.example whose name the attacker points at
  // 127.0.0.1 reaches the server, but with its own name in the Host header.
  ServingRun serving;
  const int port = serving.port;
  httplib::Client client("127.0.0.1", port);
  for (const std::string& host : {fmt::format("127.0.0.1:{}", port), fmt::format("localhost:{}", port),
                                 fmt::format("LocalHost:{}", port), fmt::format("[::1]:{}", port)}) {
    const auto answer = client.Get("/map.bin", {{"Host", host}});
    ASSERT_TRUE(answer) << host;
    EXPECT_EQ(answer->status, 200) << host;
  }
  for (const std::string& host : {fmt::format("evil.example:{}", port), std::string("evil.example"),
                                 std::string("127.0.0.1"), fmt::format("127.0.0.1:{}", port + 1),
                                 fmt::format("127.0.0.1.evil.example:{}", port), fmt::format("x127.0.0.1:{}", port),
                                 std::string("")}) {
    const auto answer = client.Get("/", {{"Host", host}});
    ASSERT_TRUE(answer) << host;
    EXPECT_EQ(answer->status, 403) << host;
    EXPECT_EQ(answer->body.find("<html"), std::string::npos) << host;
  }
  EXPECT_TRUE(viewer_host_allowed(fmt::format("localhost:{}", port), port));
  EXPECT_FALSE(viewer_host_allowed(fmt::format("localhost:{}0", port), port));
  EXPECT_FALSE(viewer_host_allowed(":8080", 8080));
}

// Bounded memory (issue #39): a request body beyond 64 KiB is refused (413),
// not buffered; the server keeps answering.
TEST(Viewer, LargeRequestBodiesAreRefused) {
  ServingRun serving;
  httplib::Client client("127.0.0.1", serving.port);
  const httplib::Headers host{{"Host", fmt::format("127.0.0.1:{}", serving.port)}};
  const auto big = client.Post("/", host, std::string(4 << 20, 'x'), "application/octet-stream");
  ASSERT_TRUE(big);
  EXPECT_EQ(big->status, 413);
  const auto small = client.Get("/map.bin", host);
  ASSERT_TRUE(small);
  EXPECT_EQ(small->status, 200);
}

// Bounded answers (issue #53): a request for many byte ranges (the probe's
// 2,650 ranges of the page made a 2.4 GB answer) is refused, small; one range is served.
TEST(Viewer, ManyByteRangesAreRefused) {
  ServingRun serving;
  httplib::Client client("127.0.0.1", serving.port);
  const std::string host = fmt::format("127.0.0.1:{}", serving.port);
  std::string ranges = "bytes=0-";
  for (int i = 1; i < 2650; ++i) ranges += ",0-";
  const auto many = client.Get("/", {{"Host", host}, {"Range", ranges}});
  ASSERT_TRUE(many);
  EXPECT_EQ(many->status, 416);
  EXPECT_LT(many->body.size(), 1u << 20);
  const auto one = client.Get("/", {{"Host", host}, {"Range", "bytes=0-99"}});
  ASSERT_TRUE(one);
  EXPECT_EQ(one->status, 206);
  EXPECT_EQ(one->body.size(), 100u);
  const auto page = client.Get("/", {{"Host", host}});
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
}

TEST(Viewer, IdleConnectionsDoNotStallTheServer) {
  // Twelve connections that send nothing (more than httplib's default pool
  // of 8 workers, each of which would wait 5 s on one): a request still
  // gets its answer at once.
  ServingRun serving;
  std::vector<int> idle;
  for (int i = 0; i < 12; ++i) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    ASSERT_GE(fd, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(serving.port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0);
    idle.push_back(fd);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the server has accepted them
  httplib::Client client("127.0.0.1", serving.port);
  const auto start = std::chrono::steady_clock::now();
  const auto answer = client.Get("/map.bin");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(answer);
  EXPECT_EQ(answer->status, 200);
  EXPECT_LT(seconds, 1.5);
  for (const int fd : idle) ::close(fd);
}

// A saved map of two sessions made by hand: session 0 six keyframes 5 m
// apart along x, session 1 four keyframes from x = 10 m, 2 m beside it.
// Keyframe k has 20 + k road points along its x axis and 5 building points
// above y = 10 m. Odometry edges within each session, one loop edge within
// session 0 (0-5) and two across (2-7, 3-8).
constexpr std::size_t kMapKeyframes = 10;
std::size_t keyframe_points(std::size_t k) { return 20 + k + 5; }

void write_two_session_map(const fs::path& folder) {
  SavedMap map;
  map.manifest.sessions = {MapSession{"/data/first", 0, 6, true}, MapSession{"/data/second", 10, 4, true}};
  std::vector<StoredFeatures> features;
  for (std::size_t k = 0; k < kMapKeyframes; ++k) {
    MapKeyframe kf;
    kf.session = k < 6 ? 0 : 1;
    kf.frame = kf.session == 0 ? k : k - 6;
    kf.pose.translation() = kf.session == 0 ? Eigen::Vector3d(5.0 * static_cast<double>(k), 0, 0)
                                            : Eigen::Vector3d(10 + 5.0 * static_cast<double>(k - 6), 2, 0);
    kf.odometry_pose = kf.pose;  // no loop correction
    map.keyframes.push_back(kf);
    PlaceDescriptor place;  // the default detector's (Scan Context's 20 x 60); the viewer does not read it
    place.context = scan_context_from_descriptor(Eigen::MatrixXf::Zero(20, 60));
    map.places.push_back(place);
    StoredFeatures f;
    for (std::size_t i = 0; i < 20 + k; ++i) {
      f.planar_points.emplace_back(static_cast<float>(i), 0.0F, -1.7F);
      f.planar_classes.push_back(to_learning_class(cls::kRoad));
    }
    for (std::size_t i = 0; i < 5; ++i) {
      f.edge_points.emplace_back(0.0F, 10.0F, static_cast<float>(i));
      f.edge_classes.push_back(to_learning_class(cls::kBuilding));
    }
    features.push_back(f);
  }
  const auto edge = [&](std::size_t from, std::size_t to, EdgeKind kind) {
    map.edges.push_back({from, to, map.keyframes[from].pose.inverse() * map.keyframes[to].pose, Matrix6d::Identity(),
                         kind});
  };
  for (std::size_t k = 1; k < kMapKeyframes; ++k)
    if (k != 6) edge(k - 1, k, EdgeKind::kOdometry);
  edge(0, 5, EdgeKind::kLoop);
  edge(2, 7, EdgeKind::kLoop);
  edge(3, 8, EdgeKind::kLoop);
  write_map(folder, map, [&](std::size_t k) -> const StoredFeatures& { return features[k]; });
}

TEST(Viewer, SavedMapGivesATrajectoryPerSessionAndItsLoopEdges) {
  TempDir tmp;
  write_two_session_map(tmp / "map");
  ASSERT_TRUE(is_map_folder(tmp / "map"));
  const ViewerScene scene = load_viewer_scene(tmp / "map");
  ASSERT_EQ(scene.sessions.size(), 2U);
  EXPECT_EQ(scene.sessions[0].frames, (std::vector<std::size_t>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(scene.sessions[1].frames, (std::vector<std::size_t>{6, 7, 8, 9}));
  EXPECT_EQ(scene.sessions[1].name, "/data/second");
  EXPECT_TRUE(scene.sessions[1].linked);
  ASSERT_EQ(scene.loop_closed.size(), kMapKeyframes);
  EXPECT_NEAR((scene.loop_closed[7].translation() - Eigen::Vector3d(15, 2, 0)).norm(), 0.0, 1e-12);
  using Edges = std::vector<std::pair<std::size_t, std::size_t>>;
  EXPECT_EQ(scene.loops, (Edges{{0, 5}}));
  EXPECT_EQ(scene.cross_session_loops, (Edges{{2, 7}, {3, 8}}));

  // The map: every feature point, placed by its keyframe's pose.
  std::size_t points = 0;
  for (std::size_t k = 0; k < kMapKeyframes; ++k) points += keyframe_points(k);
  EXPECT_EQ(scene.map_points_total, points);
  ASSERT_EQ(scene.map.size(), points);
  float max_x = 0;
  std::size_t buildings = 0;
  for (std::size_t i = 0; i < scene.map.size(); ++i) {
    max_x = std::max(max_x, scene.map.points[i].x());
    buildings += scene.map.label[i] == cls::kBuilding;
  }
  EXPECT_FLOAT_EQ(max_x, 25.0F + 28.0F);  // keyframe 9 at x = 25 m, its last road point 28 m ahead
  EXPECT_EQ(buildings, 5 * kMapKeyframes);
  // The scan at the slider: the keyframe's features in its own frame.
  const LabelledCloud scan = load_viewer_scan(scene, 7, 1000);
  EXPECT_EQ(scan.size(), keyframe_points(7));

  ViewerPageStats stats;
  const auto data = testing::page_data(viewer_page(scene, {}, ViewerDataSource::kEmbedded, &stats));
  EXPECT_EQ(data["kind"], "map");
  ASSERT_EQ(data["trajectories"].size(), 2U);
  EXPECT_EQ(data["trajectories"][0]["count"], "6 keyframes");
  EXPECT_EQ(data["trajectories"][1]["count"], "4 keyframes");
  EXPECT_EQ(data["trajectories"][1]["name"], "session 1: second");
  EXPECT_NE(data["trajectories"][0]["color"], data["trajectories"][1]["color"]);
  EXPECT_EQ(decoded_size(data["trajectories"][1]["positions"].get<std::string>()), 4U * 3U * sizeof(float));
  EXPECT_EQ(data["loops"].size(), 1U);
  EXPECT_EQ(data["cross_loops"].size(), 2U);
  EXPECT_EQ(data["frames"], kMapKeyframes);
  EXPECT_EQ(stats.sessions, 2U);
  EXPECT_EQ(stats.cross_session_loops, 2U);
  EXPECT_EQ(stats.scans, kMapKeyframes);
  EXPECT_EQ(default_viewer_page(tmp / "map"), tmp / "map.view.html");
  EXPECT_EQ(default_viewer_page(tmp / "map/"), tmp / "map.view.html");
}

TEST(Viewer, SavedMapKeepsToTheBudgetOneKeyframeAtATime) {
  TempDir tmp;
  write_two_session_map(tmp / "map");
  ViewerOptions options;
  options.max_map_points = 100;  // 10 points a keyframe
  const ViewerScene scene = load_viewer_scene(tmp / "map", options);
  EXPECT_EQ(scene.map.size(), 100U);
  EXPECT_GT(scene.map_points_total, 100U);
  float max_x = 0;
  for (const auto& p : scene.map.points) max_x = std::max(max_x, p.x());
  EXPECT_GT(max_x, 25.0F) << "the last keyframe has its share";
}

TEST(Viewer, BadSavedMapGivesClearErrors) {
  TempDir tmp;
  write_two_session_map(tmp / "map");
  ViewerOptions options;
  options.sequence = tmp.path();
  EXPECT_NE(testing::input_error_of([&] { load_viewer_scene(tmp / "map", options); }).find("drop --sequence"),
            std::string::npos);
  fs::resize_file(tmp / "map/keyframes.bin", fs::file_size(tmp / "map/keyframes.bin") - 5);
  const std::string error = testing::input_error_of([&] { load_viewer_scene(tmp / "map"); });
  EXPECT_NE(error.find("keyframes.bin"), std::string::npos) << error;
}

}  // namespace
}  // namespace saloam
