// The saved map's format (docs/map_format.md): what is written reads back
// the same, and the reader refuses broken maps, naming the file.

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fstream>
#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "saloam/core/error.hpp"
#include "saloam/core/folder_replace.hpp"
#include "saloam/core/digest.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/maps/map_format.hpp"
#include "saloam/maps/prior_map.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

Pose random_pose(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(3 * u(rng), Eigen::Vector3d(u(rng), u(rng), 1).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(100 * u(rng), 100 * u(rng), 5 * u(rng));
  return orthonormalized(T);
}

// A keyframe's motion from the one before: 1-3 m ahead, turning a little.
Pose small_step(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(0.1 * u(rng), Eigen::Vector3d(0.1 * u(rng), 0.1 * u(rng), 1).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(2 + u(rng), 0.2 * u(rng), 0.05 * u(rng));
  return orthonormalized(T);
}

StoredFeatures random_features(std::mt19937& rng, std::size_t n) {
  std::uniform_real_distribution<float> u(-50, 50);
  StoredFeatures f;
  for (std::size_t i = 0; i < n; ++i) {
    f.edge_points.emplace_back(u(rng), u(rng), u(rng) / 10);
    f.edge_classes.push_back(static_cast<ClassIndex>(i % kNumClassIndices));
    f.planar_points.emplace_back(u(rng), u(rng), u(rng) / 10);
    f.planar_classes.push_back(static_cast<ClassIndex>((3 * i) % kNumClassIndices));
  }
  return f;
}

// A map with every kind of descriptor part, odometry and loop edges.
struct TestMap {
  SavedMap map;
  std::vector<StoredFeatures> features;
};

TestMap make_map(std::size_t keyframes) {
  std::mt19937 rng(7);
  TestMap t;
  t.map.config.loop.detector = "ssc";
  t.map.manifest.sensor = "vlp16";
  t.map.manifest.source = "/data/run";
  t.map.manifest.first_frame = 12;
  t.map.manifest.camera_frame_outputs = true;
  t.map.manifest.velo_to_cam = random_pose(rng);
  const Pose map_from_odometry = random_pose(rng);
  std::uniform_real_distribution<float> u(0, 10);
  for (std::size_t k = 0; k < keyframes; ++k) {
    MapKeyframe kf;
    kf.frame = 3 * k;
    kf.timestamp = 0.3 * static_cast<double>(k);
    kf.travelled = 1.5 * static_cast<double>(k);
    // The odometry poses chain the odometry edges' measurements; the
    // optimised poses are the odometry's in the map frame, a loop's
    // correction (10 cm) apart (read_map checks both).
    const Pose step = k == 0 ? Pose::Identity() : small_step(rng);
    kf.odometry_pose = k == 0 ? random_pose(rng) : orthonormalized(t.map.keyframes.back().odometry_pose * step);
    kf.pose = orthonormalized(map_from_odometry * kf.odometry_pose * Eigen::Translation3d(0.1, 0, 0));
    t.map.keyframes.push_back(kf);
    PlaceDescriptor p;
    Eigen::MatrixXf sc(20, 60);
    for (Eigen::Index i = 0; i < sc.size(); ++i) sc.data()[i] = u(rng) - 1;
    p.context = scan_context_from_descriptor(sc);
    for (int i = 0; i < 30; ++i) {
      p.ssc.points.emplace_back(u(rng) * 3, u(rng) * 3);
      p.ssc.codes.push_back(static_cast<std::uint8_t>(1 + i % 11));
    }
    p.ssc.key_range.assign(static_cast<std::size_t>(t.map.config.loop.ssc.key_sectors), 0.0F);
    p.ssc.key_points.assign(p.ssc.key_range.size(), Eigen::Vector2f::Zero());
    p.ssc.key_range[2] = 4.5F;
    p.ssc.key_points[2] = {4.0F, 2.0F};
    p.ssc.cells = ssc_cells(p.ssc.points, p.ssc.codes, SscAlignment{}, t.map.config.loop.ssc);
    p.graph.nodes = {1, 5, 11};
    p.graph.centers = {{1, 2, 3}, {-4, 5, 0.5}, {7, -8, 1}};
    for (int i = 0; i < kSgprEmbeddingSize; ++i) p.embedding[i] = static_cast<float>(i) / 7.0F;
    t.map.places.push_back(p);
    t.features.push_back(random_features(rng, 5 + k));
    if (k > 0) {
      PoseGraphEdge e;
      e.from = k - 1;
      e.to = k;
      e.measured = step;
      Matrix6d a = Matrix6d::Random();
      e.information = a * a.transpose() + Matrix6d::Identity();
      t.map.edges.push_back(e);
    }
  }
  PoseGraphEdge loop;
  loop.from = 0;
  loop.to = keyframes - 1;
  loop.kind = EdgeKind::kLoop;
  loop.measured = random_pose(rng);
  loop.information = 3 * Matrix6d::Identity();
  t.map.edges.push_back(loop);
  return t;
}

void write_test_map(const std::filesystem::path& folder, const TestMap& t) {
  write_map(folder, t.map, [&](std::size_t k) -> const StoredFeatures& { return t.features[k]; });
}

TEST(MapFormat, RoundTripIsExact) {
  testing::TempDir dir("saloam_map_roundtrip");
  const TestMap t = make_map(6);
  write_test_map(dir / "map", t);
  const SavedMap read = read_map(dir / "map");
  EXPECT_EQ(read.manifest.version, kMapFormatVersion);
  EXPECT_EQ(read.manifest.detector, "ssc");
  EXPECT_EQ(read.manifest.sensor, "vlp16");
  EXPECT_EQ(read.manifest.source, "/data/run");
  EXPECT_EQ(read.manifest.first_frame, 12u);
  EXPECT_EQ(read.manifest.loop_edges, 1u);
  EXPECT_TRUE(read.manifest.camera_frame_outputs);
  EXPECT_TRUE(read.manifest.velo_to_cam.isApprox(t.map.manifest.velo_to_cam, 1e-12));
  EXPECT_EQ(read.config.loop.detector, "ssc");
  ASSERT_EQ(read.keyframes.size(), t.map.keyframes.size());
  for (std::size_t k = 0; k < read.keyframes.size(); ++k) {
    EXPECT_EQ(read.keyframes[k].frame, t.map.keyframes[k].frame);
    EXPECT_EQ(read.keyframes[k].timestamp, t.map.keyframes[k].timestamp);
    EXPECT_EQ(read.keyframes[k].travelled, t.map.keyframes[k].travelled);
    EXPECT_TRUE(read.keyframes[k].pose.isApprox(t.map.keyframes[k].pose, 1e-12));
    EXPECT_TRUE(read.keyframes[k].odometry_pose.isApprox(t.map.keyframes[k].odometry_pose, 1e-12));
    const PlaceDescriptor &a = read.places[k], &b = t.map.places[k];
    EXPECT_EQ(a.context.descriptor, b.context.descriptor);
    EXPECT_EQ(a.context.ring_key, b.context.ring_key);
    EXPECT_EQ(a.context.unit_columns, b.context.unit_columns);
    EXPECT_EQ(a.ssc.points, b.ssc.points);
    EXPECT_EQ(a.ssc.codes, b.ssc.codes);
    EXPECT_EQ(a.ssc.cells, b.ssc.cells);
    EXPECT_EQ(a.ssc.key_range, b.ssc.key_range);
    EXPECT_EQ(a.ssc.key_points, b.ssc.key_points);
    EXPECT_EQ(a.graph.nodes, b.graph.nodes);
    EXPECT_EQ(a.graph.centers, b.graph.centers);
    EXPECT_EQ(a.embedding, b.embedding);
    const StoredFeatures f = read_map_features(dir / "map", k);
    EXPECT_EQ(f.edge_points, t.features[k].edge_points);
    EXPECT_EQ(f.edge_classes, t.features[k].edge_classes);
    EXPECT_EQ(f.planar_points, t.features[k].planar_points);
    EXPECT_EQ(f.planar_classes, t.features[k].planar_classes);
  }
  ASSERT_EQ(read.edges.size(), t.map.edges.size());
  for (std::size_t e = 0; e < read.edges.size(); ++e) {
    EXPECT_EQ(read.edges[e].from, t.map.edges[e].from);
    EXPECT_EQ(read.edges[e].to, t.map.edges[e].to);
    EXPECT_EQ(read.edges[e].kind, t.map.edges[e].kind);
    EXPECT_TRUE(read.edges[e].measured.isApprox(t.map.edges[e].measured, 1e-12));
    EXPECT_TRUE(read.edges[e].information.isApprox(t.map.edges[e].information, 1e-12));
  }
}

TEST(MapFormat, PriorMapReadsFeaturesOnDemandWithinItsCache) {
  testing::TempDir dir("saloam_map_lazy");
  const TestMap t = make_map(8);
  write_test_map(dir / "map", t);
  const PriorMap map = PriorMap::open(dir / "map", 3);
  EXPECT_EQ(map.loads(), 0u);
  for (std::size_t k = 0; k < 8; ++k) EXPECT_EQ(map.features(k)->edge_points, t.features[k].edge_points);
  EXPECT_EQ(map.loads(), 8u);
  EXPECT_EQ(map.cached(), 3u);
  (void)map.features(7);  // cached: not read again
  EXPECT_EQ(map.loads(), 8u);
  (void)map.features(0);  // evicted: read again
  EXPECT_EQ(map.loads(), 9u);
  const auto near = map.near(t.map.keyframes[4].pose.translation(), 0.01);
  ASSERT_EQ(near.size(), 1u);
  EXPECT_EQ(near[0], 4u);
}

TEST(MapFormat, ReplacesAnEarlierMapButNothingElse) {
  testing::TempDir dir("saloam_map_replace");
  write_test_map(dir / "map", make_map(4));
  const TestMap bigger = make_map(7);
  write_test_map(dir / "map", bigger);
  EXPECT_EQ(read_map(dir / "map").keyframes.size(), 7u);
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().filename(), "map") << "left behind: " << entry.path();
  }
  std::filesystem::create_directories(dir / "other");
  std::ofstream(dir / "other" / "notes.txt") << "mine\n";
  const std::string error = testing::input_error_of([&] { write_test_map(dir / "other", bigger); });
  EXPECT_NE(error.find("is not a saloam map"), std::string::npos) << error;
  EXPECT_TRUE(std::filesystem::exists(dir / "other" / "notes.txt"));
}

// A writer killed at any step of a replacement (each file of the new map,
// the exchange or the renames, the removal of the old one) leaves a whole
// map that the next reader finds: the old one before the step that puts the
// new one in place, the new one from it on. The next writer tidies what the
// killed one left, and nothing else stays beside the map.
TEST(MapFormat, AWriterKilledAtAnyStepLeavesAWholeMap) {
  const TestMap old_map = make_map(4);
  const TestMap new_map = make_map(7);
  for (const bool exchange : {true, false}) {
    SCOPED_TRACE(exchange ? "renameat2 RENAME_EXCHANGE" : "two renames");
    std::vector<std::string> steps;
    {
      testing::TempDir dir("saloam_map_steps");
      write_test_map(dir / "map", old_map);
      set_folder_replace_test_hooks([&](std::string_view step) { steps.emplace_back(step); }, exchange);
      write_test_map(dir / "map", new_map);
      set_folder_replace_test_hooks(nullptr);
    }
    const auto commit = std::find_if(steps.begin(), steps.end(),
                                     [](const std::string& s) { return s == "exchanged" || s == "renamed"; });
    ASSERT_NE(commit, steps.end());
    ASSERT_EQ(steps.back(), "removed");
    for (std::size_t k = 0; k < steps.size(); ++k) {
      SCOPED_TRACE("killed at " + steps[k]);
      testing::TempDir dir("saloam_map_kill");
      write_test_map(dir / "map", old_map);
      const pid_t child = ::fork();
      ASSERT_GE(child, 0);
      if (child == 0) {
        std::size_t seen = 0;
        set_folder_replace_test_hooks([&](std::string_view) { if (seen++ == k) ::kill(::getpid(), SIGKILL); }, exchange);
        write_test_map(dir / "map", new_map);
        ::_exit(0);
      }
      int status = 0;
      ASSERT_EQ(::waitpid(child, &status, 0), child);
      ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
      const std::size_t expected = k < static_cast<std::size_t>(commit - steps.begin()) ? 4u : 7u;
      EXPECT_EQ(read_map(dir / "map").keyframes.size(), expected);
      write_test_map(dir / "map", make_map(5));
      EXPECT_EQ(read_map(dir / "map").keyframes.size(), 5u);
      for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
        EXPECT_EQ(entry.path().filename(), "map") << "left behind: " << entry.path();
      }
    }
  }
}

TEST(MapFormat, SessionsRoundTrip) {
  testing::TempDir dir("saloam_map_sessions");
  TestMap t = make_map(7);
  for (std::size_t k = 4; k < 7; ++k) {
    t.map.keyframes[k].session = 1;
    t.map.keyframes[k].frame = k - 4;      // frames and path start again in a new session
    t.map.keyframes[k].travelled = 0.5 * static_cast<double>(k - 4);
  }
  t.map.manifest.sessions = {MapSession{"/data/a", 12, 0, true}, MapSession{"/data/b", 3, 0, false}};
  t.map.edges.erase(t.map.edges.begin() + 3);  // no odometry edge 3 -> 4 between the sessions
  PoseGraphEdge cross;
  cross.from = 1;
  cross.to = 5;
  cross.kind = EdgeKind::kLoop;
  cross.information = 2 * Matrix6d::Identity();
  t.map.edges.push_back(cross);
  write_test_map(dir / "map", t);
  const SavedMap read = read_map(dir / "map");
  ASSERT_EQ(read.manifest.sessions.size(), 2u);
  EXPECT_EQ(read.manifest.sessions[0].source, "/data/a");
  EXPECT_EQ(read.manifest.sessions[0].keyframes, 4u);
  EXPECT_TRUE(read.manifest.sessions[0].linked);
  EXPECT_EQ(read.manifest.sessions[1].source, "/data/b");
  EXPECT_EQ(read.manifest.sessions[1].first_frame, 3u);
  EXPECT_EQ(read.manifest.sessions[1].keyframes, 3u);
  EXPECT_FALSE(read.manifest.sessions[1].linked);
  EXPECT_EQ(read.manifest.cross_session_loops, 2u);  // 1 -> 5, and make_map's loop 0 -> 6
  for (std::size_t k = 0; k < 7; ++k) EXPECT_EQ(read.keyframes[k].session, k < 4 ? 0u : 1u);
}

// Rewrites `file` with one change made by `edit` on its bytes.
void edit_file(const std::filesystem::path& file, const std::function<void(std::string&)>& edit) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  edit(bytes);
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

// The map in `folder` as version 1 wrote it: every table's version 1, no
// session per keyframe, a manifest without sessions.
void downgrade_to_version_1(const std::filesystem::path& folder) {
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
    if (entry.path().extension() == ".bin") edit_file(entry.path(), [](std::string& b) { b[8] = 1; });
  }
  edit_file(folder / "keyframes.bin", [](std::string& b) {
    std::string v1 = b.substr(0, 24);
    for (std::size_t at = 24; at + 220 <= b.size(); at += 220) v1 += b.substr(at, 216);
    b = v1;
  });
  edit_file(folder / "map.json", [](std::string& b) {
    nlohmann::json j = nlohmann::json::parse(b);
    j["version"] = 1;
    j.erase("sessions");
    j.erase("cross_session_loops");
    b = j.dump(2);
  });
}

// map.json's digests made those of the files as they are now (a test that
// damages a file within what the digest sees, to reach the parser's checks).
void refresh_digests(const std::filesystem::path& folder) {
  edit_file(folder / "map.json", [&](std::string& b) {
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(b);
    for (const std::string_view file : kMapDigestedFiles) {
      std::ifstream in(folder / file, std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      j["digests"][std::string(file)] = digest_text(fnv1a64(bytes));
    }
    b = j.dump(2);
  });
}

// A map knows itself (version 3): an id drawn at each save, the digest of
// every file, and a configuration that holds every key.
TEST(MapFormat, AMapKnowsItself) {
  testing::TempDir dir("saloam_map_digests");
  const TestMap t = make_map(4);
  write_test_map(dir / "map", t);
  const SavedMap read = read_map(dir / "map");
  EXPECT_EQ(read.manifest.id.size(), 32u);
  EXPECT_EQ(read.feature_digests.size(), 4u);
  write_test_map(dir / "again", t);
  EXPECT_NE(read_map(dir / "again").manifest.id, read.manifest.id);

  // A keyframe's frame changed within bounds: its table no longer has its digest.
  write_test_map(dir / "changed", t);
  edit_file(dir / "changed/keyframes.bin", [](std::string& b) { b[24] = 9; });
  std::string error = testing::input_error_of([&] { (void)read_map(dir / "changed"); });
  EXPECT_NE(error.find((dir / "changed/keyframes.bin").string() + ": its digest"), std::string::npos) << error;

  // config.yaml cut at a line: refused by its digest, and with the digest made to fit, by its missing keys.
  write_test_map(dir / "cut", t);
  edit_file(dir / "cut/config.yaml", [](std::string& b) { b.resize(b.find('\n', b.size() / 2) + 1); });
  error = testing::input_error_of([&] { (void)read_map(dir / "cut"); });
  EXPECT_NE(error.find("config.yaml: its digest"), std::string::npos) << error;
  refresh_digests(dir / "cut");
  error = testing::input_error_of([&] { (void)read_map(dir / "cut"); });
  EXPECT_NE(error.find("config.yaml: holds no "), std::string::npos) << error;
  EXPECT_NE(error.find("is the file cut?"), std::string::npos) << error;

  // A map replaced while a run reads its features lazily: the run stops.
  write_test_map(dir / "live", t);
  const PriorMap live = PriorMap::open(dir / "live", 1);
  EXPECT_EQ(live.features(0)->planar_points, t.features[0].planar_points);
  TestMap other = make_map(4);
  other.features[1].planar_points[0].x() += 1.0F;
  write_test_map(dir / "live", other);
  error = testing::input_error_of([&] { (void)live.features(1); });
  EXPECT_NE(error.find("map replaced or changed under this run"), std::string::npos) << error;
  EXPECT_NE(error.find((dir / "live/features/000001.bin").string()), std::string::npos) << error;
}

// A map's graph agrees with its keyframes and manifest (issue #39): an edit
// whose digests were fitted to it is still refused when it moves a keyframe,
// changes an edge or the manifest's loop counts.
TEST(MapFormat, EditsThatFitTheDigestsAreRefusedByTheGraph) {
  testing::TempDir dir("saloam_map_graph");
  const TestMap t = make_map(5);
  const auto refused = [&](const std::string& name, const std::function<void(TestMap&)>& edit) {
    TestMap changed = t;
    edit(changed);
    write_test_map(dir / name, changed);  // written whole: every digest fits
    return testing::input_error_of([&] { (void)read_map(dir / name); });
  };
  EXPECT_EQ(refused("whole", [](TestMap&) {}), "no error");

  // A keyframe moved 9,900 km: refused by its odometry edges.
  std::string error = refused("moved", [](TestMap& m) { m.map.keyframes[2].pose.translation().x() += 9.9e6; });
  EXPECT_NE(error.find((dir / "moved/keyframes.bin").string() + ": keyframes 1 and 2: their poses are"), std::string::npos)
      << error;
  // Moved by half a metre along a 2 m edge: within a loop's correction.
  EXPECT_EQ(refused("nudged", [](TestMap& m) { m.map.keyframes[2].pose.translation().z() += 0.5; }), "no error");

  // An edge measuring 5,000 m between keyframes 2 m apart.
  error = refused("long_edge", [](TestMap& m) { m.map.edges[1].measured.translation().x() = 5000; });
  EXPECT_NE(error.find((dir / "long_edge/edges.bin").string() + ": odometry edge 1: measures 499"), std::string::npos)
      << error;
  // The odometry poses moved with it: the optimised poses still disagree.
  error = refused("long_edge_and_odometry", [](TestMap& m) {
    m.map.edges[1].measured.translation().x() += 5000;
    for (std::size_t k = 2; k < m.map.keyframes.size(); ++k) {
      m.map.keyframes[k].odometry_pose = m.map.keyframes[k - 1].odometry_pose * m.map.edges[k - 1].measured;
    }
  });
  EXPECT_NE(error.find("keyframes 1 and 2: their poses are"), std::string::npos) << error;
  // An odometry edge that skips a keyframe.
  error = refused("skip", [](TestMap& m) { m.map.edges[1].to = 3; });
  EXPECT_NE(error.find("odometry edge 1: keyframes 1 -> 3 are not consecutive"), std::string::npos) << error;

  // The manifest's loop count (map.json has no digest of itself).
  write_test_map(dir / "loops", t);
  edit_file(dir / "loops/map.json", [](std::string& b) {
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(b);
    j["loop_edges"] = 2;
    b = j.dump(2);
  });
  error = testing::input_error_of([&] { (void)read_map(dir / "loops"); });
  EXPECT_NE(error.find("1 loop edges (0 between sessions), map.json says 2 (0)"), std::string::npos) << error;
}

// Bounded memory (issue #39): a table larger than its header's records can
// take is refused before it is read (a map table once was read whole, up to
// 16 GiB, and copied before its header was looked at).
TEST(MapFormat, ATableLargerThanItsHeaderAllowsIsNotRead) {
  testing::TempDir dir("saloam_map_sizes");
  const TestMap t = make_map(3);
  for (const std::string name : {"keyframes.bin", "edges.bin", "digests.bin", "features/000001.bin"}) {
    SCOPED_TRACE(name);
    const auto folder = dir / ("map_" + std::to_string(name.size()));
    write_test_map(folder, t);
    edit_file(folder / name, [](std::string& b) { b.append(std::size_t{1} << 20, '\0'); });
    const std::string error = testing::input_error_of([&] {
      const SavedMap map = read_map(folder);
      (void)read_map_features(map, 1);
    });
    EXPECT_NE(error.find((folder / name).string() + ": "), std::string::npos) << error;
    EXPECT_NE(error.find("records can take: not read"), std::string::npos) << error;
  }
  EXPECT_EQ(max_map_record_bytes(MapTable::kKeyframes, SaloamConfig{}), 220u);
}

TEST(MapFormat, ReadsVersion1Maps) {
  testing::TempDir dir("saloam_map_v1");
  const TestMap t = make_map(5);
  write_test_map(dir / "map", t);
  downgrade_to_version_1(dir / "map");
  const SavedMap read = read_map(dir / "map");
  EXPECT_EQ(read.manifest.version, 1u);
  ASSERT_EQ(read.manifest.sessions.size(), 1u);
  EXPECT_EQ(read.manifest.sessions[0].source, "/data/run");
  EXPECT_EQ(read.manifest.sessions[0].first_frame, 12u);
  EXPECT_EQ(read.manifest.sessions[0].keyframes, 5u);
  EXPECT_TRUE(read.manifest.sessions[0].linked);
  ASSERT_EQ(read.keyframes.size(), 5u);
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(read.keyframes[k].session, 0u);
    EXPECT_EQ(read.keyframes[k].frame, t.map.keyframes[k].frame);
    EXPECT_TRUE(read.keyframes[k].odometry_pose.isApprox(t.map.keyframes[k].odometry_pose, 1e-12));
  }
  EXPECT_EQ(read.edges.size(), t.map.edges.size());
  EXPECT_EQ(read_map_features(dir / "map", 4).planar_points, t.features[4].planar_points);
  // Written again, it is a map of the current version.
  write_map(dir / "again", read, [&](std::size_t k) -> const StoredFeatures& { return t.features[k]; });
  EXPECT_EQ(read_map(dir / "again").manifest.version, kMapFormatVersion);
}

TEST(MapFormat, ReaderNamesTheFileAndTheProblem) {
  testing::TempDir dir("saloam_map_broken");
  const TestMap t = make_map(4);
  const auto broken = [&](const std::string& name, const std::string& file,
                          const std::function<void(std::string&)>& edit, std::string named = "") {
    const std::filesystem::path folder = dir / name;
    write_test_map(folder, t);
    edit_file(folder / file, edit);
    if (file != "map.json") refresh_digests(folder);  // past the digests, to the parser's own checks
    std::string error = testing::input_error_of([&] {
      (void)read_map(folder);
      if (file.starts_with("features")) (void)read_map_features(folder, 0);
    });
    EXPECT_NE(error.find((folder / (named.empty() ? file : named)).string()), std::string::npos) << error;
    return error;
  };
  const auto put_double = [](std::string& bytes, std::size_t at, double v) { std::memcpy(bytes.data() + at, &v, 8); };
  EXPECT_NE(broken("version", "keyframes.bin", [](std::string& b) { b[8] = 4; }).find("format version 4"),
            std::string::npos);
  EXPECT_NE(broken("magic", "edges.bin", [](std::string& b) { b[0] = 'X'; }).find("magic"), std::string::npos);
  EXPECT_NE(broken("truncated", "places.bin", [](std::string& b) { b.resize(b.size() - 3); }).find("truncated"),
            std::string::npos);
  EXPECT_NE(broken("trailing", "keyframes.bin", [](std::string& b) { b += "x"; }).find("trailing"), std::string::npos);
  // Keyframe 1's first pose value (after the header, keyframe 0's 220 bytes and 24 bytes of frame, time, length).
  EXPECT_NE(broken("nan", "keyframes.bin", [&](std::string& b) { put_double(b, 24 + 220 + 24, std::nan("")); })
                .find("not finite"),
            std::string::npos);
  EXPECT_NE(broken("rotation", "keyframes.bin", [&](std::string& b) { put_double(b, 24 + 24, 3.0); }).find("orthonormal"),
            std::string::npos);
  EXPECT_NE(broken("node", "edges.bin", [](std::string& b) { b[24] = 99; }).find("nodes 99"), std::string::npos);
  EXPECT_NE(broken("information", "edges.bin", [&](std::string& b) { put_double(b, 24 + 12 + 96, -5.0); })
                .find("positive definite"),
            std::string::npos);
  EXPECT_NE(broken("count", "map.json",
                   [](std::string& b) { b.replace(b.find("\"keyframes\": 4"), 14, "\"keyframes\": 5"); })
                .find("the sessions hold 4 keyframes, \"keyframes\" says 5"),
            std::string::npos);
  // Keyframe 1's session (the last 4 bytes of its record) set to 2: sessions follow one another from 0.
  EXPECT_NE(broken("session", "keyframes.bin", [](std::string& b) { b[24 + 2 * 220 - 4] = 2; })
                .find("session 2 after session 0"),
            std::string::npos);
  // Keyframe 3 in a second session the manifest does not list.
  EXPECT_NE(broken("sessions", "keyframes.bin", [](std::string& b) { b[24 + 4 * 220 - 4] = 1; })
                .find("session 1; map.json lists 1"),
            std::string::npos);
  EXPECT_NE(broken("format", "map.json", [](std::string& b) { b.replace(b.find("saloam-map"), 10, "other-map!"); })
                .find("not a saloam map"),
            std::string::npos);
  EXPECT_NE(broken("class", "features/000000.bin", [](std::string& b) { b[24 + 16 + 12] = 100; }).find("class index 100"),
            std::string::npos);
}

}  // namespace
}  // namespace saloam
