// KITTI raw's text files: timestamps, oxts records and their poses, the
// IMU-to-Velodyne calibration.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <sstream>

#include "saloam/core/lie.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/kitti_raw.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

using testing::input_error_of;

TEST(KittiRaw, TimestampsAreNanosecondsSinceTheEpoch) {
  std::istringstream in("2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.074898283\r\n\n2011-09-27 00:00:00\n");
  const auto t = parse_kitti_timestamps_ns(in, "timestamps.txt");
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0], 1317042145 * kNanosPerSecond + 964389445);  // date -u -d '2011-09-26 13:02:25' +%s = 1317042145
  EXPECT_EQ(t[1] - t[0], 110508838);
  EXPECT_EQ(t[2], 1317081600 * kNanosPerSecond);
}

TEST(KittiRaw, TimestampsWriteAndReadBack) {
  testing::TempDir dir;
  const std::vector<double> t{1317042145.0, 1317042145.1, 1317042145.2 + 86400.0 * 400};
  write_kitti_timestamps(dir / "t.txt", t);
  const auto back = read_kitti_timestamps_ns(dir / "t.txt");
  ASSERT_EQ(back.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(nanos_to_seconds(back[i]), t[i], 1e-6);
}

// Nanoseconds stay exact: times relative to a drive's first scan come back as
// written (in seconds since the epoch a double keeps only about 0.2 us).
TEST(KittiRaw, TimestampsAreExactNanoseconds) {
  std::istringstream in("2011-09-26 13:02:25.000000000\n2011-09-26 13:02:25.100000000\n2011-09-26 13:02:25.1000000006\n");
  const auto ns = parse_kitti_timestamps_ns(in, "timestamps.txt");
  ASSERT_EQ(ns.size(), 3u);
  EXPECT_EQ(ns[0], 1317042145 * kNanosPerSecond);
  EXPECT_EQ(ns[1] - ns[0], 100000000);
  EXPECT_EQ(ns[2] - ns[1], 1);  // a tenth digit rounds (a double of seconds since 1970 could not tell them apart)
  EXPECT_EQ(nanos_to_seconds(ns[1] - ns[0]), 0.1);
  testing::TempDir dir;
  write_kitti_timestamps_ns(dir / "t.txt", ns);
  EXPECT_EQ(read_kitti_timestamps_ns(dir / "t.txt"), ns);
}

TEST(KittiRaw, BadTimestampsNameTheLine) {
  const auto error_of = [](const std::string& text) {
    std::istringstream in(text);
    return input_error_of([&] { parse_kitti_timestamps_ns(in, "ts.txt"); });
  };
  EXPECT_NE(error_of("2011-09-26 13:02:25.9\n2011-13-26 13:02:25.9\n").find("ts.txt: line 2: '2011-13-26 13:02:25.9' is not a KITTI timestamp"), std::string::npos);
  EXPECT_NE(error_of("2011-09-26 13:02:25.9\n2011-09-26 13:02:25.8\n").find("ts.txt: line 2: timestamp"), std::string::npos);
  EXPECT_NE(error_of("1317042145.9\n").find("line 1"), std::string::npos);
  // Years whose nanoseconds since 1970 do not fit 64 bits (the fuzzer's 0000).
  EXPECT_NE(error_of("0000-01-01 00:00:00.0\n").find("line 1: '0000-01-01 00:00:00.0' is not a KITTI timestamp"),
            std::string::npos);
  EXPECT_NE(error_of("9999-12-31 23:59:59.9\n").find("is not a KITTI timestamp"), std::string::npos);
}

TEST(KittiRaw, OxtsRecordsBecomePosesAndBack) {
  OxtsRecord origin{49.011, 8.4236, 112.0, 0.01, -0.02, 1.0};
  std::vector<Pose> imu(3, Pose::Identity());
  imu[1].translation() = Eigen::Vector3d(10.0, 0.5, 0.1);
  imu[2] = imu[1] * se3_exp((Vector6d() << 0.01, 0.02, 0.3, 9.0, -1.0, 0.2).finished());
  const auto records = poses_to_oxts(imu, origin);
  EXPECT_NEAR(records[0].lat, origin.lat, 1e-12);
  EXPECT_NEAR(records[0].yaw, origin.yaw, 1e-12);
  const auto back = oxts_to_poses(records);
  ASSERT_EQ(back.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_LT((back[i].matrix() - imu[i].matrix()).norm(), 1e-6) << i;
  }
}

TEST(KittiRaw, OxtsFilesReadAndWrite) {
  testing::TempDir dir;
  const OxtsRecord r{49.01, 8.42, 113.5, 0.03, -0.01, 2.5};
  write_oxts(dir / "0000000000.txt", r);
  const OxtsRecord back = read_oxts(dir / "0000000000.txt");
  EXPECT_DOUBLE_EQ(back.lat, r.lat);
  EXPECT_DOUBLE_EQ(back.yaw, r.yaw);
  std::ifstream in(dir / "0000000000.txt");
  std::string line;
  std::getline(in, line);
  std::istringstream words(line);
  EXPECT_EQ(std::distance(std::istream_iterator<std::string>(words), {}), 30);

  const auto error_of = [](const std::string& text) {
    std::istringstream in(text);
    return input_error_of([&] { parse_oxts(in, "o.txt"); });
  };
  EXPECT_NE(error_of("49 8 100\n").find("o.txt: 3 numbers: an oxts record has 30"), std::string::npos);
  EXPECT_NE(error_of("49 8 100 0 0 nan\n").find("'nan' is not a finite number"), std::string::npos);
  EXPECT_NE(error_of("89 8 100 0 0 0\n").find("latitude 89 deg is beyond"), std::string::npos);
  EXPECT_NE(error_of(std::string(31 * 2, ' ') + [] { std::string s; for (int i = 0; i < 31; ++i) s += "1 "; return s; }()).find("more than 30"), std::string::npos);
}

TEST(KittiRaw, ImuToVeloCalibration) {
  testing::TempDir dir;
  std::ofstream(dir / "c.txt") << "calib_time: 25-May-2012 16:47:16\nR: 9.999976e-01 7.553071e-04 -2.035826e-03 "
                                  "-7.854027e-04 9.998898e-01 -1.482298e-02 2.024406e-03 1.482454e-02 9.998881e-01\n"
                                  "T: -8.086759e-01 3.195559e-01 -7.997231e-01\n";
  const Pose T = read_imu_to_velo(dir / "c.txt");
  EXPECT_NEAR(T.translation().x(), -0.8086759, 1e-9);
  EXPECT_NEAR(T.linear()(1, 2), -1.482298e-02, 1e-6);
  write_imu_to_velo(dir / "d.txt", T);
  EXPECT_LT((read_imu_to_velo(dir / "d.txt").matrix() - T.matrix()).norm(), 1e-12);
  std::ofstream(dir / "e.txt") << "R: 1 0 0 0 1 0 0 0 1\n";
  EXPECT_NE(input_error_of([&] { read_imu_to_velo(dir / "e.txt"); }).find("needs a line 'T: ' with 3 numbers"), std::string::npos);
  std::ofstream(dir / "f.txt") << "R: 2 0 0 0 1 0 0 0 1\nT: 0 0 0\n";
  EXPECT_NE(input_error_of([&] { read_imu_to_velo(dir / "f.txt"); }).find("line 1: rotation R is not orthonormal"), std::string::npos);
}

// The published reference of drive 0005: IMU poses from convertOxtsToPose
// (TUM) and the LiDAR poses derived from them with calib_imu_to_velo. The
// conversion saloam applies to oxts poses (Q = T_velo<-imu P T_velo<-imu^-1)
// must turn the one into the other.
TEST(KittiRaw, SharedDriveLidarPosesAreTheImuPosesThroughTheCalibration) {
  SALOAM_REQUIRE_SHARED_DATA();
  const Trajectory imu = read_tum_trajectory(testing::shared_file("data/kitti_raw_0005/poses_oxts_imu_tum.txt"));
  const auto lidar = read_kitti_poses(testing::shared_file("data/kitti_raw_0005/poses.txt"));
  const Pose velo_imu = read_imu_to_velo(testing::shared_file("data/kitti_raw_0005/calib_imu_to_velo.txt"));
  ASSERT_EQ(imu.size(), lidar.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < lidar.size(); ++i) {
    const Pose Q = velo_imu * imu.poses[i] * velo_imu.inverse();
    worst = std::max(worst, (Q.translation() - lidar[i].translation()).norm());
  }
  EXPECT_LT(worst, 1e-3);
}

}  // namespace
}  // namespace saloam
