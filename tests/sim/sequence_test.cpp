#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>
#include <fstream>
#include <iterator>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/sim/label_noise.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sim/trajectories.hpp"
#include "sim/sim_fixture.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using saloam::testing::TempDir;

std::string bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

SimulationOptions small_options() {
  SimulationOptions o;
  o.preset = "urban-loop";
  o.first_frame = 200;
  o.end_frame = 206;
  o.stride = 2;
  o.beams = 16;
  o.azimuth_steps = 700;
  o.seed = 3;
  o.show_progress = false;
  return o;
}

TEST(Sequence, SameSeedSameBytes) {
  TempDir a, b, c;
  const SimulationOptions options = small_options();
  const auto sa = simulate_sequence(options, a.path());
  simulate_sequence(options, b.path());
  SimulationOptions other = options;
  other.seed = 4;
  simulate_sequence(other, c.path());
  ASSERT_EQ(sa.frames, 3u);
  for (const std::string name : {"velodyne/000000.bin", "velodyne/000002.bin", "labels/000001.label", "poses.txt",
                                 "times.txt", "calib.txt"}) {
    ASSERT_TRUE(fs::exists(a / name)) << name;
    EXPECT_EQ(bytes(a / name), bytes(b / name)) << name;
  }
  EXPECT_NE(bytes(a / "velodyne/000000.bin"), bytes(c / "velodyne/000000.bin"));
}

TEST(Sequence, ReadsBackWithKittiConventions) {
  TempDir dir;
  const SimulationOptions options = small_options();
  const auto summary = simulate_sequence(options, dir.path());
  const SequenceReader reader(dir.path());
  ASSERT_EQ(reader.size(), 3u);
  EXPECT_TRUE(reader.has_labels());
  EXPECT_TRUE(reader.has_times_file());
  // Stride 2: frames 0.2 s apart (true time, 10 Hz sensor).
  EXPECT_NEAR(reader.times()[0], 0.0, 1e-9);
  EXPECT_NEAR(reader.times()[1], 0.2, 1e-6);
  EXPECT_NEAR(reader.times()[2], 0.4, 1e-6);
  const Pose tr = reader.velo_to_cam();
  EXPECT_TRUE(tr.isApprox(kitti_velo_to_cam(), 1e-9));
  // P_0 = I and Q_k = Q_200^-1 Q_(200+2k) of the preset (LiDAR frame).
  EXPECT_TRUE(reader.camera_poses()[0].isApprox(Pose::Identity(), 1e-9));
  const auto lidar = reader.lidar_poses();
  const auto& source = testing::urban_loop();
  for (std::size_t k = 0; k < 3; ++k) {
    const Pose expected = source[200].inverse() * source[200 + 2 * k];
    EXPECT_LT((lidar[k].translation() - expected.translation()).norm(), 1e-6);
    EXPECT_LT(rotation_angle(lidar[k].inverse() * expected), 1e-6);
  }
  std::size_t points = 0;
  for (std::size_t k = 0; k < reader.size(); ++k) {
    const LabelledCloud cloud = reader.load_scan(k);
    EXPECT_GT(cloud.size(), 3000u);
    EXPECT_TRUE(cloud.has_labels);
    points += cloud.size();
  }
  EXPECT_EQ(points, summary.points);
}

TEST(Sequence, KittiTrajectoryInput) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto dir_kitti = saloam::testing::shared_file("data/kitti");
  SimulationOptions options = small_options();
  options.camera_poses = read_kitti_poses(dir_kitti / "poses/00.txt");
  options.velo_to_cam = read_velo_to_cam(dir_kitti / "calib_velo_to_cam.txt", 0);
  options.velo_to_cam_given = true;
  options.first_frame = 1000;
  options.end_frame = 1002;
  options.stride = 1;
  TempDir dir;
  simulate_sequence(options, dir.path());
  const SequenceReader reader(dir.path());
  ASSERT_EQ(reader.size(), 2u);
  // Written camera poses are the KITTI ones re-based: P'_k = P_1000^-1 P_(1000+k).
  const auto& P = options.camera_poses;
  const Pose expected = P[1000].inverse() * P[1001];
  EXPECT_LT((reader.camera_poses()[1].translation() - expected.translation()).norm(), 1e-6);
  // LiDAR motion follows the README convention: Tr^-1 P_i^-1 P_j Tr.
  const Pose tr = options.velo_to_cam;
  const Pose lidar_motion = tr.inverse() * P[1000].inverse() * P[1001] * tr;
  const auto lidar = reader.lidar_poses();
  EXPECT_LT((lidar[1].translation() - lidar_motion.translation()).norm(), 1e-6);
  // The road is under the sensor there too.
  const LabelledCloud cloud = reader.load_scan(0);
  std::size_t road = 0;
  for (auto l : cloud.label) road += l == cls::kRoad ? 1 : 0;
  EXPECT_GT(road, cloud.size() / 10);
}

TEST(Sequence, StopRequestKeepsAValidPartialSequence) {
  TempDir dir;
  SimulationOptions o = small_options();
  o.first_frame = 0;
  o.end_frame = 400;
  o.stride = 1;
  // Ask to stop (as Ctrl-C does) once a few scans are on disk.
  std::atomic<bool> done{false};
  std::thread watcher([&] {
    while (!done) {
      std::error_code ec;
      if (fs::exists(dir / "velodyne" / "000002.bin", ec)) {
        request_stop();
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  const auto summary = simulate_sequence(o, dir.path());
  done = true;
  watcher.join();
  stop_flag().store(false);
  EXPECT_TRUE(summary.interrupted);
  ASSERT_GE(summary.frames, 3u);
  ASSERT_LT(summary.frames, 400u);
  const SequenceReader reader(dir.path());
  EXPECT_EQ(reader.size(), summary.frames);
  EXPECT_EQ(read_kitti_poses(dir / "poses.txt").size(), summary.frames);
  EXPECT_EQ(read_times(dir / "times.txt").size(), summary.frames);
  EXPECT_NO_THROW(reader.load_scan(summary.frames - 1));
}

TEST(Sequence, BadOptionsAreClearErrors) {
  TempDir dir;
  SimulationOptions o = small_options();
  o.first_frame = 5000;
  o.end_frame = 6000;
  EXPECT_THROW(simulate_sequence(o, dir.path()), ConfigError);
  o = small_options();
  o.stride = 0;
  EXPECT_THROW(simulate_sequence(o, dir.path()), ConfigError);
  o = small_options();
  o.beams = 40;
  EXPECT_THROW(simulate_sequence(o, dir.path()), ConfigError);
  o = small_options();
  o.preset = "moon-base";
  EXPECT_THROW(simulate_sequence(o, dir.path()), ConfigError);
  o = small_options();
  o.camera_poses = {Pose::Identity(), Pose::Identity()};
  EXPECT_THROW(simulate_sequence(o, dir.path()), ConfigError);  // no Tr given
}

TEST(LabelNoise, NoisyLabelsReachTheStatedMiouAndKeepTruth) {
  TempDir dir;
  SimulationOptions o = small_options();
  o.beams = 64;
  o.azimuth_steps = 2083;
  o.labels = LabelMode::kNoisy;
  o.first_frame = 0;
  o.end_frame = 1000;
  o.stride = 200;  // five places around the loop
  const auto summary = simulate_sequence(o, dir.path());
  ASSERT_EQ(summary.frames, 5u);
  // Tuned for 55-65 % over long runs; five frames scatter a little more.
  EXPECT_GT(summary.miou, 0.52);
  EXPECT_LT(summary.miou, 0.70);
  EXPECT_GT(summary.label_accuracy, 0.75);
  EXPECT_LT(summary.label_accuracy, 0.95);
  // labels/ has the network-like labels, labels_gt/ the truth; scoring the files gives the printed mIoU.
  SegmentationScore score;
  for (std::size_t k = 0; k < 5; ++k) {
    const auto truth = read_label_file(dir / ("labels_gt/" + frame_name(k) + ".label"));
    const auto noisy = read_label_file(dir / ("labels/" + frame_name(k) + ".label"));
    ASSERT_EQ(truth.size(), noisy.size());
    std::vector<std::uint16_t> t, n;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      t.push_back(static_cast<std::uint16_t>(truth[i] & 0xffff));
      n.push_back(static_cast<std::uint16_t>(noisy[i] & 0xffff));
      ASSERT_EQ(noisy[i] >> 16, 0u);            // no instances from a network
      ASSERT_FALSE(is_moving(n.back()));        // single-scan networks do not tell moving from parked
    }
    score.add(t, n);
  }
  EXPECT_NEAR(score.miou(), summary.miou, 1e-12);
  // Deterministic per seed.
  const SimulatedScan scan = testing::scan_at(300, 16);
  EXPECT_EQ(emulate_segmentation(scan, 16, 2083, 5), emulate_segmentation(scan, 16, 2083, 5));
  EXPECT_NE(emulate_segmentation(scan, 16, 2083, 5), emulate_segmentation(scan, 16, 2083, 6));
}

TEST(LabelNoise, ScoreOfPerfectLabelsIsOne) {
  SegmentationScore score;
  const std::vector<std::uint16_t> truth{cls::kRoad, cls::kRoad, cls::kCar, cls::kMovingCar, cls::kBuilding, cls::kOtherStructure};
  score.add(truth, truth);
  EXPECT_DOUBLE_EQ(score.miou(), 1.0);
  SegmentationScore half;
  half.add({cls::kRoad, cls::kRoad}, {cls::kRoad, cls::kSidewalk});
  EXPECT_DOUBLE_EQ(half.iou(to_learning_class(cls::kRoad)), 0.5);
  EXPECT_DOUBLE_EQ(half.miou(), 0.5);  // sidewalk is not in the truth: not averaged
}

}  // namespace
}  // namespace saloam
