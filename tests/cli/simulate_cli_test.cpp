// End-to-end: `saloam simulate` (presets, KITTI trajectories, noisy labels,
// bad options) and `saloam render`.

#include <cairo.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/sequence.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::cli_path;
using testing::run_command;
using testing::shared_file;
using testing::TempDir;

using testing::quoted;

std::string simulate(const fs::path& out, const std::string& extra) {
  return quoted(cli_path()) + " simulate --out " + quoted(out) + " --beams 16 --azimuth-steps 600 " + extra;
}

TEST(SimulateCli, PresetWritesAReadableSequence) {
  TempDir dir;
  const fs::path seq = dir / "seq";
  std::string output;
  ASSERT_EQ(run_command(simulate(seq, "--preset figure-eight --frames 10:14 --seed 5"), &output), 0) << output;
  EXPECT_NE(output.find("wrote 4 frames"), std::string::npos) << output;
  const SequenceReader reader(seq);
  EXPECT_EQ(reader.size(), 4u);
  EXPECT_TRUE(reader.has_labels());
  EXPECT_TRUE(reader.has_poses());
  EXPECT_TRUE(reader.has_calib());
  EXPECT_EQ(reader.load_scan(3).size(), reader.load_scan(3).label.size());
}

// KITTI 08's start (its ground truth climbs 9 m in 13 m) used to give
// shrinking and empty scans; now every scan is full and the command says
// where the trajectory's height did not fit the ground.
TEST(SimulateCli, Kitti08StartHasNoEmptyScans) {
  SALOAM_REQUIRE_SHARED_DATA();
  TempDir dir;
  const fs::path seq = dir / "seq";
  const auto poses = shared_file("data/kitti/poses/08.txt");
  const auto calib = shared_file("data/kitti/calib_velo_to_cam.txt");
  std::string output;
  ASSERT_EQ(run_command(simulate(seq, "--trajectory " + quoted(poses) + " --calib " + quoted(calib) + " --frames 0:40 --stride 5"),
                        &output),
            0)
      << output;
  EXPECT_NE(output.find("wrote 8 frames"), std::string::npos) << output;
  EXPECT_NE(output.find("does not fit one ground surface"), std::string::npos) << output;
  const SequenceReader reader(seq);
  ASSERT_EQ(reader.size(), 8u);
  for (std::size_t i = 0; i < reader.size(); ++i) {
    // 16 x 600 rays; a street scene returns most of them, 08's steep start
    // with a car parked alongside about a third (see kitti_ground_test.cpp).
    EXPECT_GT(reader.load_scan(i).size(), 2400u) << "frame " << i;
  }
}

TEST(SimulateCli, KittiTrajectoryWithPerSequenceCalibList) {
  SALOAM_REQUIRE_SHARED_DATA();
  TempDir dir;
  const fs::path seq = dir / "seq";
  const auto poses = shared_file("data/kitti/poses/04.txt");
  const auto calib = shared_file("data/kitti/calib_velo_to_cam.txt");
  std::string output;
  ASSERT_EQ(run_command(simulate(seq, "--trajectory " + quoted(poses) + " --calib " + quoted(calib) + " --frames 0:2"), &output), 0)
      << output;
  // The sequence number comes from the pose file's name: Tr of line 04.
  const SequenceReader reader(seq);
  EXPECT_TRUE(reader.velo_to_cam().isApprox(read_velo_to_cam(calib, 4), 1e-9));
  EXPECT_FALSE(reader.velo_to_cam().isApprox(read_velo_to_cam(calib, 0), 1e-6));
  // A KITTI calib.txt (with a Tr: line) works as well: use the one just written.
  const fs::path seq2 = dir / "seq2";
  ASSERT_EQ(run_command(simulate(seq2, "--trajectory " + quoted(poses) + " --calib " + quoted(seq / "calib.txt") + " --frames 0:1"),
                        &output),
            0)
      << output;
}

TEST(SimulateCli, NoisyLabelsPrintMiouAndKeepTruth) {
  TempDir dir;
  const fs::path seq = dir / "seq";
  std::string output;
  ASSERT_EQ(run_command(simulate(seq, "--frames 0:2 --labels noisy"), &output), 0) << output;
  EXPECT_NE(output.find("noisy labels: mIoU"), std::string::npos) << output;
  EXPECT_TRUE(fs::exists(seq / "labels_gt" / "000001.label"));
  EXPECT_TRUE(fs::exists(seq / "labels" / "000001.label"));
}

TEST(SimulateCli, BadOptionsGiveClearErrors) {
  SALOAM_REQUIRE_SHARED_DATA();
  TempDir dir;
  std::string output;
  EXPECT_NE(run_command(simulate(dir / "a", "--frames 5:2"), &output), 0);
  EXPECT_NE(output.find("--frames"), std::string::npos) << output;
  EXPECT_NE(run_command(simulate(dir / "b", "--frames 99999:100000"), &output), 0);
  EXPECT_NE(output.find("selects nothing"), std::string::npos) << output;
  const auto poses = shared_file("data/kitti/poses/00.txt");
  EXPECT_NE(run_command(simulate(dir / "c", "--trajectory " + quoted(poses)), &output), 0);
  EXPECT_NE(output.find("--calib"), std::string::npos) << output;
  EXPECT_NE(run_command(simulate(dir / "d", "--preset nowhere"), &output), 0);
  EXPECT_NE(run_command(simulate(dir / "e", "--labels maybe"), &output), 0);
  // A calibration list without a line for the pose file's sequence.
  const fs::path renamed = dir / "42.txt";
  fs::copy_file(poses, renamed);
  EXPECT_NE(run_command(simulate(dir / "f", "--trajectory " + quoted(renamed) + " --calib " +
                                             quoted(shared_file("data/kitti/calib_velo_to_cam.txt"))),
                        &output),
            0);
  EXPECT_NE(output.find("42"), std::string::npos) << output;
}

// A sensor tilted on its mount and scans in a turned frame (issue #50): the
// scans keep their points' distances, Tr maps them to the level camera, so
// poses.txt stays the vehicle's; "R P Y" as one word or three; a wrong
// count or a word that is no angle is a clear error.
TEST(SimulateCli, TiltedMountAndTurnedFrame) {
  TempDir dir;
  std::string output;
  ASSERT_EQ(run_command(simulate(dir / "level", "--frames 0:2"), &output), 0) << output;
  ASSERT_EQ(run_command(simulate(dir / "turned", "--frames 0:2 --cloud-frame-rpy '0 20 0'"), &output), 0) << output;
  ASSERT_EQ(run_command(simulate(dir / "tilted", "--frames 0:2 --mount-rpy 0 20 0"), &output), 0) << output;
  const SequenceReader level(dir / "level"), turned(dir / "turned"), tilted(dir / "tilted");
  const LabelledCloud a = level.load_scan(1), b = turned.load_scan(1);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); i += 97) EXPECT_NEAR(a.points[i].norm(), b.points[i].norm(), 1e-4);
  EXPECT_GT((a.points[a.size() / 2] - b.points[a.size() / 2]).norm(), 0.1);
  // The camera's poses are the vehicle's; the LiDAR poses follow each frame.
  for (const SequenceReader* r : {&turned, &tilted}) {
    EXPECT_TRUE(r->camera_poses()[1].isApprox(level.camera_poses()[1], 1e-6));
  }
  const Eigen::Matrix3d turn = (level.velo_to_cam().linear().transpose() * turned.velo_to_cam().linear()).transpose();
  EXPECT_NEAR(Eigen::AngleAxisd(turn).angle() * 180.0 / M_PI, 20.0, 1e-3);
  std::ifstream record(dir / "tilted" / "simulation.yaml");
  const std::string recorded((std::istreambuf_iterator<char>(record)), std::istreambuf_iterator<char>());
  EXPECT_NE(recorded.find("mount_rpy_deg: 0 20 0"), std::string::npos) << recorded;
  // A tilted sensor sees other points, not the same ones turned.
  EXPECT_NE(a.size(), tilted.load_scan(1).size());
  for (const std::string bad : {"--mount-rpy '0 20'", "--mount-rpy '0 x 0'", "--cloud-frame-rpy '0 0 nan'",
                                "--mount-rpy '0 400 0'"}) {
    EXPECT_NE(run_command(simulate(dir / "bad", "--frames 0:1 " + bad), &output), 0) << bad;
    EXPECT_NE(output.find("deg"), std::string::npos) << bad << ": " << output;
  }
}

TEST(RenderCli, WritesMapAndRangeImage) {
  TempDir dir;
  const fs::path seq = dir / "seq";
  std::string output;
  ASSERT_EQ(run_command(simulate(seq, "--frames 0:3"), &output), 0) << output;
  ASSERT_EQ(run_command(quoted(cli_path()) + " render " + quoted(seq) + " --out " + quoted(dir / "png") + " --frame 2", &output), 0)
      << output;
  EXPECT_GT(fs::file_size(dir / "png" / "map.png"), 5000u);
  EXPECT_GT(fs::file_size(dir / "png" / "range_000002.png"), 2000u);
  EXPECT_NE(run_command(quoted(cli_path()) + " render " + quoted(seq) + " --out " + quoted(dir / "png") + " --frame 7", &output), 0);
  EXPECT_NE(output.find("out of range"), std::string::npos) << output;
}

/// Pixels of map.png in a shade of `colour` (the map darkens by relief, to 72 %).
int pixels_of(const fs::path& png, const Rgb& colour) {
  cairo_surface_t* surface = cairo_image_surface_create_from_png(png.c_str());
  int count = 0;
  if (cairo_surface_status(surface) == CAIRO_STATUS_SUCCESS) {
    cairo_surface_flush(surface);
    const int width = cairo_image_surface_get_width(surface), height = cairo_image_surface_get_height(surface);
    const int stride = cairo_image_surface_get_stride(surface);
    const unsigned char* data = cairo_image_surface_get_data(surface);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const unsigned char* p = data + y * stride + 4 * x;  // B, G, R, A
        const double shade = static_cast<double>(p[0]) / std::max<int>(colour.b, 1);
        const auto near = [shade](int pixel, int full) { return std::abs(pixel - shade * full) <= 2.0; };
        count += shade >= 0.7 && shade <= 1.0 && near(p[2], colour.r) && near(p[1], colour.g);
      }
    }
  }
  cairo_surface_destroy(surface);
  return count;
}

TEST(RenderCli, TheMapShowsTheGivenLabels) {
  TempDir dir;
  const fs::path seq = dir / "seq";
  std::string output;
  ASSERT_EQ(run_command(simulate(seq, "--frames 0:3"), &output), 0) << output;
  // Another labels folder that calls every point a car.
  fs::create_directories(dir / "cars");
  for (const auto& entry : fs::directory_iterator(seq / "labels")) {
    const std::vector<std::uint32_t> cars(fs::file_size(entry.path()) / 4, cls::kCar);
    std::ofstream(dir / "cars" / entry.path().filename(), std::ios::binary)
        .write(reinterpret_cast<const char*>(cars.data()), static_cast<std::streamsize>(4 * cars.size()));
  }
  const auto render = [&](const std::string& extra, const std::string& name) {
    EXPECT_EQ(run_command(quoted(cli_path()) + " render " + quoted(seq) + " --out " + quoted(dir / name) + extra, &output), 0)
        << output;
    return pixels_of(dir / name / "map.png", class_color(cls::kCar));
  };
  const int own = render("", "own");
  const int cars = render(" --labels-dir " + quoted(dir / "cars"), "cars");
  EXPECT_GT(cars, 1000);
  EXPECT_GT(cars, 10 * own) << "own labels: " << own << " car pixels";
}

}  // namespace
}  // namespace saloam
