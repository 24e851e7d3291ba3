// The simulated IMU (sim/imu_simulation.hpp): its truth at rest and in a
// turn, its noise as the part's datasheet gives it, and the sequence's IMU
// in the frame of its scans.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/imu/imu_noise.hpp"
#include "saloam/io/imu_text.hpp"
#include "saloam/io/sequence_source.hpp"
#include "saloam/sim/imu_simulation.hpp"
#include "saloam/sim/simulator.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(SimulatedImu, ReadsGravityAtRestAndTheTurnRate) {
  // Pitched 20 deg, still: the accelerometer reads 1 g along the body's up.
  const Eigen::Matrix3d R = rotation_from_rpy(0.0, 20 * kDeg, 0.3);
  const ContinuousMotion still = [&](double) { Pose T = Pose::Identity(); T.linear() = R; return T; };
  const ImuSample at_rest = true_imu_reading(still, 1.0);
  EXPECT_LT((at_rest.acceleration - R.transpose() * Eigen::Vector3d(0, 0, kStandardGravity)).norm(), 1e-6);
  EXPECT_LT(at_rest.angular_velocity.norm(), 1e-9);
  // Turning at 90 deg/s about the world's z on a 2 m circle: the gyroscope
  // reads the rate, the accelerometer gravity plus the centripetal 4.93 m/s^2.
  const double rate = 90 * kDeg;
  const ContinuousMotion turning = [&](double t) {
    Pose T = Pose::Identity();
    T.linear() = Eigen::AngleAxisd(rate * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = T.linear() * Eigen::Vector3d(2.0, 0.0, 0.0);
    return T;
  };
  const ImuSample turn = true_imu_reading(turning, 0.7);
  EXPECT_LT((turn.angular_velocity - Eigen::Vector3d(0, 0, rate)).norm(), 1e-6);
  EXPECT_LT((turn.acceleration - Eigen::Vector3d(-2.0 * rate * rate, 0, kStandardGravity)).norm(), 1e-4);
}

// White noise of density s at rate f: sigma = s * sqrt(f) per sample; the
// turn-on bias as drawn; the same seed, the same samples.
TEST(SimulatedImu, NoiseIsThePartsDatasheet) {
  const ContinuousMotion still = [](double) { return Pose::Identity(); };
  ImuNoise part = imu_model("icm-20948");
  part.gyro_bias_random_walk = part.accel_bias_random_walk = 0.0;
  const SimulatedImu imu = simulate_imu(still, 0.0, 200.0, part, 7, true);
  ASSERT_EQ(imu.samples.size(), 20001u);
  Eigen::Vector3d gyro_sum = Eigen::Vector3d::Zero(), accel_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_sq = Eigen::Vector3d::Zero(), accel_sq = Eigen::Vector3d::Zero();
  for (const ImuSample& s : imu.samples) {
    const Eigen::Vector3d g = s.angular_velocity - imu.gyro_bias;
    const Eigen::Vector3d a = s.acceleration - imu.accel_bias - Eigen::Vector3d(0, 0, kStandardGravity);
    gyro_sum += g;
    accel_sum += a;
    gyro_sq += g.cwiseProduct(g);
    accel_sq += a.cwiseProduct(a);
  }
  const double n = static_cast<double>(imu.samples.size());
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(std::sqrt(gyro_sq[i] / n), part.gyro_noise_density * std::sqrt(part.rate_hz),
                0.03 * part.gyro_noise_density * std::sqrt(part.rate_hz));
    EXPECT_NEAR(std::sqrt(accel_sq[i] / n), part.accel_noise_density * std::sqrt(part.rate_hz),
                0.03 * part.accel_noise_density * std::sqrt(part.rate_hz));
    EXPECT_NEAR(gyro_sum[i] / n, 0.0, 5 * part.gyro_noise_density * std::sqrt(part.rate_hz / n));
  }
  EXPECT_GT(imu.gyro_bias.norm(), 0.0);
  EXPECT_LT(imu.gyro_bias.cwiseAbs().maxCoeff(), 5 * part.gyro_bias_sigma);
  const SimulatedImu again = simulate_imu(still, 0.0, 1.0, part, 7, true);
  EXPECT_EQ(again.samples[50].angular_velocity, imu.samples[50].angular_velocity);
}

// The sequence's IMU: every sweep covered, on times.txt's clock, in the
// written scans' frame (a turned cloud frame turns the samples with it);
// none for a drive, which is linear between frames.
TEST(SimulatedImu, TheSequencesImuIsInItsScansFrame) {
  SimulationOptions options;
  options.preset = "handheld-walk";
  options.first_frame = 50;
  options.end_frame = 60;
  options.show_progress = false;
  const ImuNoise part = imu_model("adis16465");
  const SimulatedImu level = SimulatedSequence(options).imu(part, false);
  EXPECT_DOUBLE_EQ(level.samples.front().time, 0.0);
  EXPECT_GE(level.samples.back().time, 1.0 - 1e-9);
  EXPECT_EQ(level.samples.size(), 401u);
  options.cloud_frame_rpy_deg = Eigen::Vector3d(0, 20, 0);
  const SimulatedImu turned = SimulatedSequence(options).imu(part, false);
  const Eigen::Matrix3d R = rotation_from_rpy_deg(options.cloud_frame_rpy_deg);
  for (std::size_t k = 0; k < level.samples.size(); k += 37) {
    EXPECT_LT((turned.samples[k].acceleration - R * level.samples[k].acceleration).norm(), 1e-9);
    EXPECT_LT((turned.samples[k].angular_velocity - R * level.samples[k].angular_velocity).norm(), 1e-12);
  }
  options.preset = "straight";
  options.cloud_frame_rpy_deg.setZero();
  EXPECT_THROW(SimulatedSequence(options).imu(part), ConfigError);
  EXPECT_THROW(imu_model("mpu-6050"), ConfigError);
  // Asked of the whole simulation, refused before anything is written.
  options.imu = "icm-20948";
  testing::TempDir dir("saloam_imu_drive");
  EXPECT_THROW(simulate_sequence(options, dir.path() / "seq"), ConfigError);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "seq"));
}

// simulate --imu writes imu.txt beside the scans; the sequence's source
// describes it (saloam info) but does not hand its up to the run (its rest
// test takes a walker setting off for rest: docs/imu.md).
TEST(SimulatedImu, TheSequencesImuTxtIsDescribedByItsSource) {
  testing::TempDir dir("saloam_imu_sequence");
  SimulationOptions options;
  options.preset = "handheld-walk";
  options.end_frame = 3;
  options.imu = "icm-20948";
  options.show_progress = false;
  ASSERT_EQ(simulate_sequence(options, dir.path()).frames, 3u);
  const std::vector<ImuSample> samples = read_imu_text(dir.path() / "imu.txt");
  EXPECT_EQ(samples.size(), 31u);  // 100 Hz over the three sweeps
  const SequenceFolderSource source{SequenceReader(dir.path())};
  const auto& notes = source.info().notes;
  EXPECT_TRUE(std::any_of(notes.begin(), notes.end(),
                          [](const std::string& n) { return n.rfind("IMU: 31 samples in imu.txt, 100 Hz", 0) == 0; }));
  EXPECT_TRUE(std::any_of(notes.begin(), notes.end(), [](const std::string& n) { return n.rfind("IMU: up (", 0) == 0; }));
  EXPECT_FALSE(source.info().imu_up.has_value());
}

}  // namespace
}  // namespace saloam
