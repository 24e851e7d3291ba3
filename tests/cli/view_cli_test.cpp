// End-to-end: `saloam view` writes the page, a headless Chromium draws it
// (no JavaScript error, a map in class colours on the canvas; a saved map's
// sessions each in its colour), and --serve serves it until Ctrl-C.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cairo.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <regex>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "saloam/maps/map_format.hpp"
#include "browser_fixture.hpp"
#include "testing/test_support.hpp"
#include "viewer/viewer_fixture.hpp"

// After Eigen: httplib.h includes <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::chromium;
using testing::cli_path;
using testing::quoted;
using testing::run_command;
using testing::TempDir;

std::string saloam_cmd(const std::string& args) { return quoted(cli_path()) + " " + args; }

TEST(ViewCli, WritesThePageWithTheBudget) {
  TempDir tmp;
  const auto run = testing::write_fake_run(tmp.path(), 8000);
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("view {} --max-points 3000", quoted(run.run_dir))), &output), 0)
      << output;
  EXPECT_NE(output.find("3000 of 8000 map points, 40 frames with ground truth"), std::string::npos) << output;
  const auto data = testing::page_data(testing::read_text(run.run_dir / "view.html"));
  EXPECT_EQ(data["map"]["count"], 3000U);
  ASSERT_EQ(
      run_command(saloam_cmd(fmt::format("view {} --out {}", quoted(run.run_dir), quoted(tmp / "p.html"))), &output), 0)
      << output;
  EXPECT_TRUE(fs::exists(tmp / "p.html"));
}

TEST(ViewCli, SlamWritesThePageBesideItsResults) {
  TempDir tmp;
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("simulate --out {} --preset straight --frames 0:6 --beams 16",
                                               quoted(tmp / "seq"))),
                        &output),
            0)
      << output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {}", quoted(tmp / "seq"), quoted(tmp / "out"))), &output),
            0)
      << output;
  EXPECT_NE(output.find("3D view: " + (tmp / "out/view.html").string()), std::string::npos) << output;
  const auto data = testing::page_data(testing::read_text(tmp / "out/view.html"));
  EXPECT_EQ(data["frames"], 6U);
  EXPECT_EQ(data["trajectories"].size(), 3U) << "ground truth found through summary.json";
  EXPECT_EQ(data["scans"]["frames"].size(), 6U);
}

TEST(ViewCli, ARunThatSavedAMapPointsToIt) {
  TempDir tmp;
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("simulate --out {} --preset straight --frames 0:10 --beams 16",
                                               quoted(tmp / "seq"))),
                        &output),
            0)
      << output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {} --save-map {}", quoted(tmp / "seq"),
                                               quoted(tmp / "out"), quoted(tmp / "map"))),
                        &output),
            0)
      << output;
  ASSERT_EQ(run_command(saloam_cmd("view " + quoted(tmp / "out")), &output), 0) << output;
  const std::string map = fs::absolute(tmp / "map").lexically_normal().string();
  EXPECT_NE(output.find("this run saved a map: saloam view " + map + "\n"), std::string::npos) << output;
  // Moved away, the map is not offered.
  fs::rename(tmp / "map", tmp / "moved");
  ASSERT_EQ(run_command(saloam_cmd("view " + quoted(tmp / "out")), &output), 0) << output;
  EXPECT_NE(output.find("this run saved a map to " + map + ", which holds no map now"), std::string::npos) << output;
  // A run that saved none says nothing of maps.
  const auto run = testing::write_fake_run(tmp / "fake", 100);
  ASSERT_EQ(run_command(saloam_cmd("view " + quoted(run.run_dir)), &output), 0) << output;
  EXPECT_EQ(output.find("saved a map"), std::string::npos) << output;
}

TEST(ViewCli, MissingMapIsAClearError) {
  TempDir tmp;
  const auto run = testing::write_fake_run(tmp.path(), 100);
  fs::remove(run.run_dir / "map.ply");
  std::string output;
  EXPECT_EQ(run_command(saloam_cmd("view " + quoted(run.run_dir)), &output), 2);
  EXPECT_NE(output.find("map.ply: not found: the global map"), std::string::npos) << output;
  EXPECT_EQ(run_command(saloam_cmd("view " + quoted(tmp / "nowhere")), &output), 2);
  EXPECT_NE(output.find("nowhere: run folder not found"), std::string::npos) << output;
}

struct PixelCounts {
  std::size_t drawn = 0;  ///< differs from the background
  std::size_t road = 0, building = 0, vegetation = 0;
};

bool near(const unsigned char* bgra, Rgb c) {
  return std::abs(bgra[2] - c.r) <= 10 && std::abs(bgra[1] - c.g) <= 10 && std::abs(bgra[0] - c.b) <= 10;
}

/// Pixels of the centre of the screenshot (away from the legend and the slider).
PixelCounts count_pixels(const fs::path& png) {
  PixelCounts counts;
  cairo_surface_t* surface = cairo_image_surface_create_from_png(png.c_str());
  if (cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS) {
    cairo_surface_destroy(surface);
    return counts;
  }
  cairo_surface_flush(surface);
  const int width = cairo_image_surface_get_width(surface), height = cairo_image_surface_get_height(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  const unsigned char* data = cairo_image_surface_get_data(surface);
  for (int y = height / 8; y < height * 7 / 8; ++y) {
    for (int x = width * 3 / 10; x < width * 9 / 10; ++x) {
      const unsigned char* p = data + y * stride + 4 * x;
      counts.drawn += !near(p, Rgb{16, 20, 24});  // the page's background
      counts.road += near(p, class_color(cls::kRoad));
      counts.building += near(p, class_color(cls::kBuilding));
      counts.vegetation += near(p, class_color(cls::kVegetation));
    }
  }
  cairo_surface_destroy(surface);
  return counts;
}

TEST(ViewCli, HeadlessChromiumDrawsTheMapWithoutErrors) {
  SALOAM_REQUIRE_CHROMIUM();
  TempDir tmp;
  const auto run = testing::write_fake_run(tmp.path(), 60'000);
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd("view " + quoted(run.run_dir)), &output), 0) << output;
  const fs::path page = run.run_dir / "view.html";

  // The page reports "ready:<map points>" in its title, or "error: ..." for any JavaScript error.
  const std::string dom = chromium(tmp, "--dump-dom", page);
  std::smatch title;
  ASSERT_TRUE(std::regex_search(dom, title, std::regex("<title>([^<]*)</title>"))) << dom.substr(0, 2000);
  EXPECT_EQ(title[1].str().rfind("ready:60000 ", 0), 0U) << title[1];
  EXPECT_EQ(dom.find("Uncaught"), std::string::npos) << dom.substr(0, 4000);
  EXPECT_EQ(dom.find(":CONSOLE"), std::string::npos) << "console output:\n" << dom.substr(0, 4000);

  const fs::path png = tmp / "view.png";
  const std::string shot = chromium(tmp, fmt::format("--screenshot={} --window-size=1024,768", quoted(png)), page);
  ASSERT_TRUE(fs::exists(png)) << shot;
  const PixelCounts counts = count_pixels(png);
  const std::size_t area = 1024 * 768 * 3 / 4 * 6 / 10;
  EXPECT_GT(counts.drawn, area / 20) << "the canvas is almost blank";
  EXPECT_GT(counts.road, 200U);
  EXPECT_GT(counts.building, 200U);
  EXPECT_GT(counts.vegetation, 100U);
}

/// Pixels of the screenshot's centre within 10 of `color` in each channel.
std::size_t pixels_of(const fs::path& png, Rgb color) {
  std::size_t count = 0;
  cairo_surface_t* surface = cairo_image_surface_create_from_png(png.c_str());
  if (cairo_surface_status(surface) == CAIRO_STATUS_SUCCESS) {
    cairo_surface_flush(surface);
    const int width = cairo_image_surface_get_width(surface), height = cairo_image_surface_get_height(surface);
    const int stride = cairo_image_surface_get_stride(surface);
    const unsigned char* data = cairo_image_surface_get_data(surface);
    for (int y = height / 8; y < height * 7 / 8; ++y)
      for (int x = width * 3 / 10; x < width * 9 / 10; ++x) count += near(data + y * stride + 4 * x, color);
  }
  cairo_surface_destroy(surface);
  return count;
}

// Two simulated passes along one street (16 beams, 60 and 70 frames,
// overlapping over 30), mapped and joined by `saloam slam --map`: a map of
// two linked sessions. The page has one trajectory per session, in its own
// colour, and the map's cross-session loop edges.
TEST(ViewCli, SavedMapShowsOneTrajectoryPerSession) {
  TempDir tmp;
  std::string output;
  for (const char* pass : {"0", "1"}) {
    ASSERT_EQ(run_command(saloam_cmd(fmt::format("simulate --preset straight --passes 0:60,30:100 --pass {} --beams 16 "
                                                 "--labels noisy --out {}",
                                                 pass, quoted(tmp / (std::string("pass") + pass)))),
                          &output),
              0)
        << output;
  }
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {} --save-map {} --no-map", quoted(tmp / "pass0"),
                                               quoted(tmp / "slamA"), quoted(tmp / "mapA"))),
                        &output),
            0)
      << output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {} --map {} --save-map {} --no-map",
                                               quoted(tmp / "pass1"), quoted(tmp / "slamAB"), quoted(tmp / "mapA"),
                                               quoted(tmp / "mapAB"))),
                        &output),
            0)
      << output;
  const SavedMap map = read_map(tmp / "mapAB");
  ASSERT_EQ(map.manifest.sessions.size(), 2U);
  ASSERT_TRUE(map.manifest.sessions[1].linked) << "the second pass did not join the first";
  ASSERT_GT(map.manifest.cross_session_loops, 0U);

  ASSERT_EQ(run_command(saloam_cmd("view " + quoted(tmp / "mapAB")), &output), 0) << output;
  EXPECT_NE(output.find(fmt::format("{} keyframes in 2 sessions", map.keyframes.size())), std::string::npos) << output;
  EXPECT_NE(output.find(fmt::format("{} across", map.manifest.cross_session_loops)), std::string::npos) << output;
  const fs::path page = tmp / "mapAB.view.html";
  ASSERT_TRUE(fs::exists(page)) << "the page goes beside the map";
  EXPECT_FALSE(fs::exists(tmp / "mapAB/view.html")) << "the map folder holds only the map";
  const auto data = testing::page_data(testing::read_text(page));
  ASSERT_EQ(data["trajectories"].size(), 2U);
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_EQ(data["trajectories"][s]["count"], fmt::format("{} keyframes", map.manifest.sessions[s].keyframes));
  }
  EXPECT_EQ(data["cross_loops"].size(), map.manifest.cross_session_loops);

  SALOAM_REQUIRE_CHROMIUM();
  const std::string dom = chromium(tmp, "--dump-dom", page);
  std::smatch title;
  ASSERT_TRUE(std::regex_search(dom, title, std::regex("<title>([^<]*)</title>"))) << dom.substr(0, 2000);
  EXPECT_EQ(title[1].str().rfind("ready:", 0), 0U) << title[1];
  EXPECT_NE(title[1].str().find("trajectories:2 "), std::string::npos) << title[1];
  EXPECT_EQ(dom.find(":CONSOLE"), std::string::npos) << "console output:\n" << dom.substr(0, 4000);
  // The legend (built by the page's script): both sessions with their keyframe counts.
  const std::string legend = dom.substr(0, dom.find("const SALOAM_DATA"));
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_NE(legend.find(fmt::format("session {}: pass{}", s, s)), std::string::npos) << legend.substr(0, 4000);
    EXPECT_NE(legend.find(fmt::format("{} keyframes", map.manifest.sessions[s].keyframes)), std::string::npos);
  }
  EXPECT_NE(legend.find("cross-session loop edges"), std::string::npos);

  // At the last keyframe (view.html#frame=N opens there): its scan, drawn
  // over the trajectories, lies at session 1's end, away from session 0's
  // start, the part of session 0 that session 1 (drawn after it) does not cover.
  const fs::path png = tmp / "map.png";
  const fs::path at_last = page.string() + fmt::format("#frame={}", map.keyframes.size() - 1);
  const std::string shot = chromium(tmp, fmt::format("--screenshot={} --window-size=1600,1200", quoted(png)), at_last);
  ASSERT_TRUE(fs::exists(png)) << shot;
  const std::size_t first = pixels_of(png, Rgb{0x3b, 0x9c, 0xff}), second = pixels_of(png, Rgb{0xff, 0x98, 0x00});
  std::cout << fmt::format("session pixels: {} and {}\n", first, second);
  EXPECT_GT(first, 20U) << "session 0's trajectory is not drawn";
  EXPECT_GT(second, 20U) << "session 1's trajectory is not drawn";
}

TEST(ViewCli, ServeAnswersUntilCtrlC) {
  TempDir tmp;
  const auto run = testing::write_fake_run(tmp.path(), 2000, 20, 1000);
  const fs::path log = tmp / "serve.log";
  const pid_t pid = testing::spawn_saloam({"view", run.run_dir.string(), "--serve", "--port", "0", "--scan-points", "700"}, log);
  ASSERT_GT(pid, 0);
  const std::optional<int> port = testing::served_port(log);
  ASSERT_TRUE(port) << testing::read_text(log);

  httplib::Client client("127.0.0.1", *port);
  const auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_EQ(testing::page_data(page->body)["source"], "server");
  const auto scan = client.Get("/scan/3");
  ASSERT_TRUE(scan);
  EXPECT_EQ(scan->body.size(), 7U * 700U);

  kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << testing::read_text(log);
  EXPECT_NE(testing::read_text(log).find("server stopped"), std::string::npos) << testing::read_text(log);
}

}  // namespace
}  // namespace saloam
