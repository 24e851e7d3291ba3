#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

using testing::input_error_of;

std::vector<Pose> spiral(std::size_t n) {
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < n; ++i) {
    Vector6d xi;
    const double s = static_cast<double>(i);
    xi << 0.9 * s, 0.1 * s, -0.01 * s, 0.001 * s, -0.002 * s, 0.03 * s;
    poses.push_back(se3_exp(xi));
  }
  return poses;
}

void write_text(const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; }

TEST(TrajectoryIo, KittiRoundTrip) {
  testing::TempDir dir;
  const auto poses = spiral(50);
  write_kitti_poses(dir / "p.txt", poses);
  const auto back = read_kitti_poses(dir / "p.txt");
  ASSERT_EQ(back.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) EXPECT_TRUE(back[i].isApprox(poses[i], 1e-8)) << i;
  const auto traj = read_trajectory(dir / "p.txt");
  EXPECT_EQ(traj.size(), 50u);
  EXPECT_DOUBLE_EQ(traj.timestamps[10], 1.0);
}

TEST(TrajectoryIo, TumRoundTrip) {
  testing::TempDir dir;
  Trajectory t;
  t.poses = spiral(20);
  for (std::size_t i = 0; i < t.size(); ++i) t.timestamps.push_back(100.0 + 0.1 * static_cast<double>(i));
  write_tum_trajectory(dir / "t.txt", t);
  const auto back = read_tum_trajectory(dir / "t.txt");
  ASSERT_EQ(back.size(), t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_NEAR(back.timestamps[i], t.timestamps[i], 1e-6);
    EXPECT_TRUE(back.poses[i].isApprox(t.poses[i], 1e-7));
  }
  EXPECT_EQ(read_trajectory(dir / "t.txt").size(), t.size());
}

TEST(TrajectoryIo, ReadsSharedGroundTruth) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto poses = read_kitti_poses(testing::shared_file("data/kitti/poses/00.txt"));
  EXPECT_EQ(poses.size(), 4541u);
  EXPECT_TRUE(poses.front().isApprox(Pose::Identity(), 1e-6));
  const auto times = read_times(testing::shared_file("data/kitti/times/00.txt"));
  EXPECT_EQ(times.size(), 4541u);
}

TEST(TrajectoryIo, BadLinesNameTheLine) {
  testing::TempDir dir;
  write_text(dir / "bad.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n");
  auto msg = input_error_of([&] { read_kitti_poses(dir / "bad.txt"); });
  EXPECT_NE(msg.find("bad.txt: line 2: expected 12 numbers"), std::string::npos) << msg;

  write_text(dir / "junk.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 x 0 1 0 0 0 0 1 0\n");
  msg = input_error_of([&] { read_kitti_poses(dir / "junk.txt"); });
  EXPECT_NE(msg.find("line 2: 'x' is not a number"), std::string::npos) << msg;

  write_text(dir / "nan.txt", "1 0 0 nan 0 1 0 0 0 0 1 0\n");
  msg = input_error_of([&] { read_kitti_poses(dir / "nan.txt"); });
  EXPECT_NE(msg.find("line 1: non-finite"), std::string::npos) << msg;

  write_text(dir / "scaled.txt", "2 0 0 0 0 2 0 0 0 0 2 0\n");
  msg = input_error_of([&] { read_kitti_poses(dir / "scaled.txt"); });
  EXPECT_NE(msg.find("not orthonormal"), std::string::npos) << msg;

  write_text(dir / "empty.txt", "\n# nothing\n");
  msg = input_error_of([&] { read_kitti_poses(dir / "empty.txt"); });
  EXPECT_NE(msg.find("no poses"), std::string::npos) << msg;

  write_text(dir / "tum.txt", "0 1 2 3 0 0 0 1\n0.1 1 2 3 0 0 0\n");
  msg = input_error_of([&] { read_tum_trajectory(dir / "tum.txt"); });
  EXPECT_NE(msg.find("line 2: expected 8 numbers"), std::string::npos) << msg;

  write_text(dir / "mixed.txt", "0 1 2 3 0 0 0 1\n1 0 0 0 0 1 0 0 0 0 1 0\n");
  msg = input_error_of([&] { read_trajectory(dir / "mixed.txt"); });
  EXPECT_NE(msg.find("line 2"), std::string::npos) << msg;

  msg = input_error_of([&] { read_kitti_poses(dir / "absent.txt"); });
  EXPECT_NE(msg.find("absent.txt: file not found"), std::string::npos) << msg;
}

// The conversion camera <-> LiDAR frame is checked against the independent
// conversion of the official ground truth stored in shared/ (scans_00/poses_lidar.txt).
TEST(Calibration, CameraToLidarMatchesSharedReference) {
  SALOAM_REQUIRE_SHARED_DATA();
  const Pose tr = read_velo_to_cam(testing::shared_file("data/kitti/calib_velo_to_cam.txt"), 0);
  auto camera = read_kitti_poses(testing::shared_file("data/kitti/poses/00.txt"));
  camera.resize(6);
  const auto lidar = camera_to_lidar_poses(camera, tr);
  const auto reference = read_kitti_poses(testing::shared_file("data/kitti/scans_00/poses_lidar.txt"));
  ASSERT_EQ(reference.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_LT((lidar[i].translation() - reference[i].translation()).norm(), 1e-5) << i;
    EXPECT_LT(rotation_angle(lidar[i].inverse() * reference[i]), 1e-6) << i;
  }
  // LiDAR forward is x: the car drives ~0.86 m/frame along +x at the start of 00.
  EXPECT_NEAR(lidar[1].translation().x(), 0.86, 0.01);
  const auto camera_back = lidar_to_camera_poses(lidar, tr);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_TRUE(camera_back[i].isApprox(camera[i], 1e-9));
}

TEST(Calibration, ReadsKittiCalibFileAndReportsMissingTr) {
  SALOAM_REQUIRE_SHARED_DATA();
  testing::TempDir dir;
  const Pose tr = read_velo_to_cam(testing::shared_file("data/kitti/calib_velo_to_cam.txt"), 4);
  write_calib(dir / "calib.txt", tr);
  EXPECT_TRUE(read_velo_to_cam(dir / "calib.txt").isApprox(tr, 1e-10));
  write_text(dir / "noTr.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0 1\n");
  EXPECT_NE(input_error_of([&] { read_velo_to_cam(dir / "noTr.txt"); }).find("no 'Tr:' line"), std::string::npos);
  write_text(dir / "shortTr.txt", "Tr: 1 0 0 0 0 1 0 0 0 0 1\n");
  EXPECT_NE(input_error_of([&] { read_velo_to_cam(dir / "shortTr.txt"); }).find("line 1"), std::string::npos);
  EXPECT_NE(input_error_of([&] { read_velo_to_cam(dir / "none.txt"); }).find("not found"), std::string::npos);
  EXPECT_NE(input_error_of([&] { read_velo_to_cam(testing::shared_file("data/kitti/calib_velo_to_cam.txt"), 42); })
                .find("no line for sequence 42"),
            std::string::npos);
}

}  // namespace
}  // namespace saloam

namespace saloam {
namespace {

using testing::input_error_of;

/// A KITTI line of `pose` with its rotation replaced by `rotation`.
std::string kitti_line(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& t = Eigen::Vector3d(1, 2, 3)) {
  Pose pose = Pose::Identity();
  pose.linear() = rotation;
  pose.translation() = t;
  return kitti_pose_line(pose) + "\n";
}

/// A rotation off SO(3) by about `amount` in ||R^T R - I||, like KITTI's
/// printed calib Tr (about 1e-4).
Eigen::Matrix3d nearly_orthonormal(double amount) {
  Eigen::Matrix3d r = so3_exp(Eigen::Vector3d(0.1, -0.2, 0.3));
  r(0, 1) += amount;
  return r;
}

TEST(TrajectoryIo, RotationsMustBeRigidNotOnlyHaveDeterminantOne) {
  testing::TempDir dir;
  const std::string good = kitti_line(Eigen::Matrix3d::Identity());
  // det = 1 but a scale and a squeeze: not a rotation.
  write_text(dir / "squeezed.txt", good + kitti_line(Eigen::Vector3d(2.0, 0.5, 1.0).asDiagonal()));
  auto msg = input_error_of([&] { read_kitti_poses(dir / "squeezed.txt"); });
  EXPECT_NE(msg.find("squeezed.txt: line 2: rotation is not orthonormal"), std::string::npos) << msg;
  msg = input_error_of([&] { read_trajectory(dir / "squeezed.txt"); });
  EXPECT_NE(msg.find("line 2: rotation is not orthonormal"), std::string::npos) << msg;

  write_text(dir / "mirror.txt", kitti_line(Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal()));
  msg = input_error_of([&] { read_kitti_poses(dir / "mirror.txt"); });
  EXPECT_NE(msg.find("line 1: rotation is a reflection"), std::string::npos) << msg;

  // Rounding like KITTI's (1e-4) is accepted and projected back onto SO(3).
  write_text(dir / "rounded.txt", good + kitti_line(nearly_orthonormal(1e-4)));
  const auto poses = read_kitti_poses(dir / "rounded.txt");
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_LT(orthonormality_error(poses[1].linear()), 1e-12);
  EXPECT_NEAR(poses[1].linear().determinant(), 1.0, 1e-12);
  write_text(dir / "sheared.txt", kitti_line(nearly_orthonormal(1e-2)));
  EXPECT_NE(input_error_of([&] { read_kitti_poses(dir / "sheared.txt"); }).find("not orthonormal"), std::string::npos);
}

TEST(TrajectoryIo, TimestampsMustIncrease) {
  testing::TempDir dir;
  write_text(dir / "times.txt", "0.0\n0.1\n# comment\n0.05\n");
  auto msg = input_error_of([&] { read_times(dir / "times.txt"); });
  EXPECT_NE(msg.find("times.txt: line 4: timestamp 0.05 is not after 0.1 on line 2"), std::string::npos) << msg;
  write_text(dir / "repeated.txt", "0.0\n0.1\n0.1\n");
  msg = input_error_of([&] { read_times(dir / "repeated.txt"); });
  EXPECT_NE(msg.find("line 3"), std::string::npos) << msg;
  write_text(dir / "inf.txt", "0.0\ninf\n");
  msg = input_error_of([&] { read_times(dir / "inf.txt"); });
  EXPECT_NE(msg.find("inf.txt: line 2: non-finite value"), std::string::npos) << msg;

  // TUM trajectories: the same rule, through both readers.
  write_text(dir / "reversed_tum.txt", "0.2 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 1\n");
  msg = input_error_of([&] { read_tum_trajectory(dir / "reversed_tum.txt"); });
  EXPECT_NE(msg.find("reversed_tum.txt: line 2: timestamp 0.1 is not after 0.2"), std::string::npos) << msg;
  msg = input_error_of([&] { read_trajectory(dir / "reversed_tum.txt"); });
  EXPECT_NE(msg.find("line 2: timestamp"), std::string::npos) << msg;
}

TEST(TrajectoryIo, ByteOrderMarkIsSkippedAndDirectoriesNamed) {
  testing::TempDir dir;
  write_text(dir / "bom.txt", "\xEF\xBB\xBF" + kitti_line(Eigen::Matrix3d::Identity()));
  ASSERT_EQ(read_kitti_poses(dir / "bom.txt").size(), 1u);
  write_text(dir / "bom_times.txt", "\xEF\xBB\xBF" "0.0\r\n0.1\r\n");
  EXPECT_EQ(read_times(dir / "bom_times.txt").size(), 2u);
  std::filesystem::create_directories(dir / "poses.txt");
  const auto msg = input_error_of([&] { read_kitti_poses(dir / "poses.txt"); });
  EXPECT_NE(msg.find("poses.txt: is a directory, not a file"), std::string::npos) << msg;
}

// Old cases of issue #39, each with its test.
TEST(TrajectoryIo, TumTimestampsKeepNanoseconds) {
  testing::TempDir dir;
  Trajectory t;
  for (int i = 0; i < 3; ++i) {
    t.timestamps.push_back(1e-9 * i);
    t.poses.push_back(Pose::Identity());
  }
  write_tum_trajectory(dir / "ns.txt", t);
  const Trajectory back = read_tum_trajectory(dir / "ns.txt");
  ASSERT_EQ(back.size(), 3u);
  EXPECT_NEAR(back.timestamps[1], 1e-9, 1e-15);
  EXPECT_NEAR(back.timestamps[2], 2e-9, 1e-15);
}

TEST(Calibration, ANonFiniteTrIsNamedSo) {
  testing::TempDir dir;
  std::ofstream(dir / "nan.txt") << "Tr: nan 0 0 0 0 1 0 0 0 0 1 0\n";
  const std::string error = input_error_of([&] { (void)read_velo_to_cam(dir / "nan.txt"); });
  EXPECT_NE(error.find("line 1: 'Tr' holds the non-finite value 'nan'"), std::string::npos) << error;
  std::ofstream(dir / "inf.txt") << "Tr: 1 0 0 0 0 1 0 1e999 0 0 1 0\n";
  EXPECT_NE(input_error_of([&] { (void)read_velo_to_cam(dir / "inf.txt"); }).find("non-finite value '1e999'"),
            std::string::npos);
}

TEST(TrajectoryIo, FormatIsReported) {
  testing::TempDir dir;
  write_text(dir / "k.txt", kitti_line(Eigen::Matrix3d::Identity()));
  write_text(dir / "t.txt", "0 1 2 3 0 0 0 1\n");
  TrajectoryFormat format{};
  read_trajectory(dir / "k.txt", &format);
  EXPECT_EQ(format, TrajectoryFormat::kKitti);
  read_trajectory(dir / "t.txt", &format);
  EXPECT_EQ(format, TrajectoryFormat::kTum);
}

TEST(Calibration, TrMustBeRigidAndMayBeIndented) {
  testing::TempDir dir;
  const auto tr_line = [](const Eigen::Matrix3d& r) { return "Tr: " + kitti_line(r); };
  write_text(dir / "indented.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n  Tr: " + kitti_line(nearly_orthonormal(1e-4)));
  const Pose tr = read_velo_to_cam(dir / "indented.txt");
  EXPECT_LT(orthonormality_error(tr.linear()), 1e-12);  // re-orthonormalised
  EXPECT_TRUE(tr.translation().isApprox(Eigen::Vector3d(1, 2, 3)));

  write_text(dir / "squeezed.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n" + tr_line(Eigen::Vector3d(2.0, 0.5, 1.0).asDiagonal()));
  const auto msg = input_error_of([&] { read_velo_to_cam(dir / "squeezed.txt"); });
  EXPECT_NE(msg.find("squeezed.txt: line 2: rotation of 'Tr' is not orthonormal"), std::string::npos) << msg;
  write_text(dir / "bom.txt", "\xEF\xBB\xBF" + tr_line(Eigen::Matrix3d::Identity()));
  EXPECT_TRUE(read_velo_to_cam(dir / "bom.txt").isApprox(Pose(Eigen::Translation3d(1, 2, 3))));
}

}  // namespace
}  // namespace saloam

namespace saloam {
namespace {

// The stream readers (what the path readers and the fuzz harnesses call)
// name the file they are given in every error, and read what the path
// readers read.
TEST(TrajectoryIo, StreamReadersMatchPathReadersAndNameTheirSource) {
  testing::TempDir dir;
  const auto poses = spiral(4);
  write_kitti_poses(dir / "poses.txt", poses);
  std::ifstream kitti(dir / "poses.txt");
  const auto from_stream = read_kitti_poses(kitti, "given.txt");
  ASSERT_EQ(from_stream.size(), poses.size());
  EXPECT_TRUE(from_stream.back().isApprox(read_kitti_poses(dir / "poses.txt").back()));

  auto error_of = [](auto read) -> std::string {
    try {
      read();
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "named.txt");
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(error_of([] {
              std::istringstream in("1 2 3\n");
              (void)read_kitti_poses(in, "named.txt");
            }),
            "named.txt: line 1: expected 12 numbers (KITTI 3x4 pose), found 3");
  EXPECT_EQ(error_of([] {
              std::istringstream in("");
              (void)read_tum_trajectory(in, "named.txt");
            }),
            "named.txt: no poses in file");
  EXPECT_EQ(error_of([] {
              std::istringstream in("0.1\n0.1\n");
              (void)read_times(in, "named.txt");
            }).substr(0, 18),
            "named.txt: line 2:");
  EXPECT_EQ(error_of([] {
              std::istringstream in("x y\n");
              (void)read_trajectory(in, "named.txt");
            }),
            "named.txt: line 1: 'x' is not a number");
  EXPECT_EQ(error_of([] {
              std::istringstream in("P0: 1 2 3\n");
              (void)read_velo_to_cam(in, "named.txt");
            }),
            "named.txt: no 'Tr:' line (velodyne to camera 0 transform)");
}

}  // namespace
}  // namespace saloam
