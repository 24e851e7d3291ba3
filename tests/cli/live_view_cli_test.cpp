// End-to-end: `saloam slam|odom|localize ... --serve` shows the run as it
// goes. A client that polls as the page does ends with the run's own
// loop-closed poses and its accepted loops (localize: its placed frames and
// the saved map); headless Chromium draws the page without
// errors; a run that ends by itself keeps its page until Ctrl-C (exit 0),
// and Ctrl-C during the run ends both (exit 130, the outputs written).

#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "browser_fixture.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/viewer/viewer_scene.hpp"
#include "viewer/viewer_fixture.hpp"

// After Eigen: httplib.h includes <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::quoted;
using testing::run_command;
using testing::TempDir;

std::string saloam_cmd(const std::string& args) { return quoted(testing::cli_path()) + " " + args; }

/// What a client polling as the live page does holds: the poses merged
/// across revisions, the loops, and the revisions it saw.
struct Follower {
  std::uint64_t revision = 0;
  std::vector<float> poses;  ///< 12 a frame
  nlohmann::json state = nlohmann::json::object();
  std::set<std::string> statuses;

  /// One poll; false when the server did not answer.
  bool poll(httplib::Client& client) {
    const auto answer = client.Get(fmt::format("/live.json?revision={}&frames={}", revision, poses.size() / 12));
    if (!answer || answer->status != 200) return false;
    state = nlohmann::json::parse(answer->body);
    const std::vector<float> news = testing::base64_floats(state["poses"]);
    const std::size_t first = state["first"];
    EXPECT_TRUE(first == poses.size() / 12 || first == 0);
    poses.resize(12 * first);
    poses.insert(poses.end(), news.begin(), news.end());
    EXPECT_EQ(poses.size(), 12 * state["frames"].get<std::size_t>());
    revision = state["revision"];
    statuses.insert(state["status"].get<std::string>());
    return true;
  }

  /// Polls twenty times a second until the run is no longer running (two minutes at most).
  void until_the_run_ends(httplib::Client& client) {
    for (int i = 0; i < 2400 && state.value("status", "running") == "running"; ++i) {
      poll(client);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
};

/// Accepted (query, match) of a loops.csv.
std::set<std::pair<std::size_t, std::size_t>> accepted_loops(const fs::path& file) {
  std::set<std::pair<std::size_t, std::size_t>> loops;
  for (const auto& [query, match] : read_accepted_loops(file)) loops.emplace(query, match);
  return loops;
}

/// A `saloam ... --serve` child, killed when a failed assertion leaves it serving.
class Child {
 public:
  Child(const std::vector<std::string>& args, const fs::path& log) : pid_(testing::spawn_saloam(args, log)) {}
  ~Child() {
    if (pid_ <= 0) return;
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  [[nodiscard]] bool started() const { return pid_ > 0; }
  void interrupt() const { kill(pid_, SIGINT); }
  /// Its exit status; -1 when it did not exit normally.
  int wait() {
    int status = 0;
    const bool waited = waitpid(pid_, &status, 0) == pid_;
    pid_ = -1;
    return waited && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
};

/// `saloam ARGS --serve --port 0` in `tmp` (its log: tmp/run.log) and a client of its page, once the log names the
/// port (`client` null when the run did not start or name it).
struct ServedRun {
  fs::path log;
  Child child;
  int port = 0;
  std::unique_ptr<httplib::Client> client;

  ServedRun(const TempDir& tmp, std::vector<std::string> args)
      : log(tmp / "run.log"), child(serving(std::move(args)), log) {
    const std::optional<int> served = child.started() ? testing::served_port(log) : std::nullopt;
    if (!served) return;
    port = *served;
    client = std::make_unique<httplib::Client>("127.0.0.1", port);
  }
  [[nodiscard]] std::string log_text() const { return testing::read_text(log); }

 private:
  static std::vector<std::string> serving(std::vector<std::string> args) {
    args.insert(args.end(), {"--serve", "--port", "0"});
    return args;
  }
};

/// A figure eight at 16 beams: 407 frames, a few seconds, loops closed.
class LiveViewCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    std::string output;
    ASSERT_EQ(run_command(saloam_cmd("-q simulate --preset figure-eight --beams 16 --azimuth-steps 900 --stride 4 --out " +
                                     quoted(*dir_ / "seq")),
                          &output),
              0)
        << output;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static fs::path sequence() { return *dir_ / "seq"; }
  static TempDir* dir_;
};
TempDir* LiveViewCli::dir_ = nullptr;

TEST_F(LiveViewCli, SlamShowsItsRunAsItGoesAndKeepsThePageUntilCtrlC) {
  TempDir tmp;
  const fs::path out = tmp / "out";
  ServedRun run(tmp, {"slam", sequence().string(), "--out", out.string(), "--no-map"});
  ASSERT_TRUE(run.client) << run.log_text();
  Follower follower;
  follower.until_the_run_ends(*run.client);
  ASSERT_EQ(follower.state.value("status", ""), "finished") << run.log_text();

  // The poses merged across revisions are the run's loop-closed poses (float32).
  const Trajectory written = read_tum_trajectory(out / "poses_tum.txt");
  ASSERT_EQ(follower.poses.size(), 12 * written.poses.size());
  double worst = 0;
  for (std::size_t f = 0; f < written.poses.size(); ++f) {
    for (int a = 0; a < 3; ++a) {
      worst = std::max(worst, std::abs(follower.poses[12 * f + 4 * a + 3] - written.poses[f].translation()[a]));
    }
  }
  EXPECT_LT(worst, 1e-3);
  std::set<std::pair<std::size_t, std::size_t>> shown;
  for (const auto& loop : follower.state["loops"]) shown.emplace(loop[0], loop[1]);
  EXPECT_EQ(shown, accepted_loops(out / "loops.csv"));
  EXPECT_GE(shown.size(), 1U);
  EXPECT_GE(follower.state["revision"].get<int>(), 1);  // loop closure moved the trajectory
  const auto map = run.client->Get("/live/map?from=0");
  ASSERT_TRUE(map);
  EXPECT_GT(map->body.size(), 8U * follower.state["chunks"].get<std::size_t>());

  SALOAM_REQUIRE_CHROMIUM();
  const std::string dom = testing::chromium_url(tmp, "--virtual-time-budget=5000 --dump-dom",
                                                fmt::format("http://127.0.0.1:{}/", run.port));
  EXPECT_NE(dom.find(fmt::format("<title>live:finished frames:{} ", written.poses.size())), std::string::npos)
      << dom.substr(0, 2000);
  EXPECT_EQ(dom.find("<title>error"), std::string::npos) << dom.substr(0, 2000);  // the page's errors go to its title

  run.child.interrupt();
  EXPECT_EQ(run.child.wait(), 0) << run.log_text();
  const std::string text = run.log_text();
  EXPECT_NE(text.find("its page stays at"), std::string::npos) << text;
  EXPECT_NE(text.find("server stopped"), std::string::npos) << text;
}

TEST_F(LiveViewCli, LocalizeShowsTheSavedMapAndTheFramesItPlaces) {
  TempDir tmp;
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("-q slam {} --frames 0:200 --no-map --out {} --save-map {}",
                                               quoted(sequence()), quoted(tmp / "mapped"), quoted(tmp / "map"))),
                        &output),
            0)
      << output;
  const fs::path out = tmp / "out";
  ServedRun run(tmp, {"localize", sequence().string(), "--frames", "100:300", "--map", (tmp / "map").string(),
                      "--out", out.string()});
  ASSERT_TRUE(run.client) << run.log_text();
  Follower follower;
  follower.until_the_run_ends(*run.client);
  ASSERT_EQ(follower.state.value("status", ""), "finished") << run.log_text();
  // The page follows the frames placed in the map: those of poses_tum.txt, in the map's frame.
  const Trajectory written = read_tum_trajectory(out / "poses_tum.txt");
  ASSERT_GT(written.poses.size(), 50U);
  ASSERT_EQ(follower.poses.size(), 12 * written.poses.size());
  EXPECT_NEAR(follower.poses[12 * 10 + 3], written.poses[10].translation().x(), 1e-3);
  EXPECT_GT(follower.state["background"]["points"].get<std::size_t>(), 1000U);
  const auto background = run.client->Get("/live/background");
  ASSERT_TRUE(background);
  EXPECT_EQ(background->body.size(), 7 * follower.state["background"]["points"].get<std::size_t>());
  run.child.interrupt();
  EXPECT_EQ(run.child.wait(), 0) << run.log_text();
}

TEST_F(LiveViewCli, APortInUseIsAClearErrorBeforeAnyOutput) {
  TempDir tmp;
  httplib::Server other;  // another program on the port
  const int port = other.bind_to_any_port("127.0.0.1");
  ASSERT_GT(port, 0);
  for (const char* command : {"slam", "odom"}) {
    std::string output;
    // (bounded: were the port taken, the run would serve until Ctrl-C)
    EXPECT_EQ(run_command("timeout 120 " + saloam_cmd(fmt::format("{} {} --out {} --serve --port {}", command,
                                                                   quoted(sequence()), quoted(tmp / command), port)),
                          &output),
              2)
        << output;
    EXPECT_NE(output.find(fmt::format("127.0.0.1:{}: cannot listen there (port in use?)", port)), std::string::npos)
        << output;
    EXPECT_FALSE(fs::exists(tmp / command)) << command;
  }
}

TEST_F(LiveViewCli, CtrlCDuringTheRunEndsTheRunAndItsPage) {
  TempDir tmp;
  const fs::path out = tmp / "out";
  ServedRun run(tmp, {"odom", sequence().string(), "--out", out.string()});
  ASSERT_TRUE(run.client) << run.log_text();
  Follower follower;
  while (follower.poll(*run.client) && follower.state["frames"].get<std::size_t>() < 20 &&
         follower.state["status"] == "running") {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  run.child.interrupt();
  const int code = run.child.wait();
  const std::string text = run.log_text();
  if (follower.state.value("status", "") == "finished") {
    EXPECT_EQ(code, 0) << text;
    GTEST_SKIP() << "the run ended before it could be interrupted (" << follower.state["frames"] << " frames)";
  }
  EXPECT_EQ(code, 130) << text;
  EXPECT_EQ(text.find("stays at"), std::string::npos) << text;
  const Trajectory written = read_tum_trajectory(out / "poses_tum.txt");
  EXPECT_GE(written.poses.size(), 20U);
  EXPECT_LT(written.poses.size(), 407U);
  EXPECT_FALSE(run.client->Get("/live.json"));  // the server is gone with the run
}

}  // namespace
}  // namespace saloam
