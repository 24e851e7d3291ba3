// The Ouster IMU: a hand-built packet decoded exactly, what is refused, the
// metadata's port and frames, unit and timing checks, and the real captures
// of ../shared/data/ouster_pcaps read as a still (or gently moving) sensor.

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

#include "saloam/core/error.hpp"
#include "saloam/sensors/ouster_imu.hpp"
#include "saloam/sensors/pcap_reader.hpp"
#include "sensors/ouster_pcaps.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

constexpr double kPi = std::numbers::pi;

/// A LEGACY IMU packet, every field written little-endian byte by byte.
std::vector<std::uint8_t> imu_packet(std::uint64_t accel_ns, std::array<float, 3> accel_g,
                                     std::array<float, 3> gyro_dps) {
  std::vector<std::uint8_t> p;
  const auto put = [&p](std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) p.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  put(accel_ns - 200'000, 8);  // system time
  put(accel_ns, 8);
  put(accel_ns + 220'000, 8);  // gyroscope time
  for (const float a : accel_g) put(std::bit_cast<std::uint32_t>(a), 4);
  for (const float w : gyro_dps) put(std::bit_cast<std::uint32_t>(w), 4);
  return p;
}

std::optional<ImuSample> decode(const std::vector<std::uint8_t>& p) {
  return decode_ouster_imu_packet(std::as_bytes(std::span(p)));
}

TEST(OusterImu, DecodesAHandBuiltPacketExactly) {
  const auto p = imu_packet(1'500'000'000'125ULL, {0.5F, -0.25F, 1.0F}, {90.0F, -180.0F, 45.0F});
  ASSERT_EQ(p.size(), kOusterImuPacketBytes);
  const auto s = decode(p);
  ASSERT_TRUE(s);
  EXPECT_DOUBLE_EQ(s->time, 1500.000000125);
  EXPECT_DOUBLE_EQ(s->acceleration.x(), 0.5 * 9.80665);
  EXPECT_DOUBLE_EQ(s->acceleration.y(), -0.25 * 9.80665);
  EXPECT_DOUBLE_EQ(s->acceleration.z(), 9.80665);
  EXPECT_DOUBLE_EQ(s->angular_velocity.x(), kPi / 2);
  EXPECT_DOUBLE_EQ(s->angular_velocity.y(), -kPi);
  EXPECT_DOUBLE_EQ(s->angular_velocity.z(), kPi / 4);
}

TEST(OusterImu, RefusesOtherSizesAndNonFiniteValues) {
  auto p = imu_packet(1000, {0, 0, 1}, {0, 0, 0});
  for (const std::size_t n : {0UL, 47UL, 49UL, 8448UL}) {
    std::vector<std::uint8_t> q(p);
    q.resize(n, 0);
    EXPECT_FALSE(decode(q)) << n << " bytes";
  }
  for (std::size_t field = 0; field < 6; ++field) {
    for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
      std::array<float, 6> v{0, 0, 1, 0, 0, 0};
      v[field] = bad;
      EXPECT_FALSE(decode(imu_packet(1000, {v[0], v[1], v[2]}, {v[3], v[4], v[5]}))) << "field " << field;
    }
  }
}

TEST(OusterImu, ReadsTheImuPortOfACapture) {
  testing::TempDir dir;
  const auto file = dir / "imu.pcap";
  {
    PcapWriter writer(file);
    writer.write(1.0, std::vector<std::uint8_t>(8448, 0), 7502);  // a lidar packet
    writer.write(1.01, imu_packet(5'000'000'000ULL, {0, 0, 1}, {0, 0, 0}), 7503);
    writer.write(1.02, std::vector<std::uint8_t>(47, 0), 7503);
    writer.write(1.03, imu_packet(5'010'000'000ULL, {std::nanf(""), 0, 1}, {0, 0, 0}), 7503);
    writer.write(1.04, imu_packet(5'020'000'000ULL, {0, 0, 1}, {0, 0, 1}), 7503);
    writer.write(1.05, imu_packet(5'030'000'000ULL, {0, 0, 1}, {0, 0, 1}), 7000);  // another port
    writer.close();
  }
  ImuReadCounts counts;
  const auto samples = read_ouster_imu(file, 7503, &counts);
  ASSERT_EQ(samples.size(), 2U);
  EXPECT_DOUBLE_EQ(samples[1].time, 5.02);
  EXPECT_EQ(counts.datagrams, 4U);
  EXPECT_EQ(counts.wrong_size, 1U);
  EXPECT_EQ(counts.non_finite, 1U);
  EXPECT_NE(testing::input_error_of([&] { (void)read_ouster_imu(dir / "none.pcap", 7503); }).find("none.pcap"),
            std::string::npos);
}

const std::string kFlat = R"({"udp_port_imu": 7600, "data_format": {"udp_profile_imu": "LEGACY"},
  "imu_to_sensor_transform": [1,0,0,6.253, 0,1,0,-11.775, 0,0,1,7.645, 0,0,0,1],
  "lidar_to_sensor_transform": [-1,0,0,0, 0,-1,0,0, 0,0,1,36.18, 0,0,0,1]})";

TEST(OusterImu, MetadataGivesThePortAndTheRotationIntoTheLidarFrame) {
  const auto flat = parse_ouster_imu_calibration(kFlat, "m.json");
  EXPECT_EQ(flat.udp_port_imu, 7600);
  EXPECT_DOUBLE_EQ(flat.imu_to_sensor(1, 3), -11.775);
  // IMU and sensor axes agree, the lidar's x and y point the other way.
  EXPECT_TRUE(flat.imu_to_lidar_rotation().isApprox(Eigen::Vector3d(-1, -1, 1).asDiagonal().toDenseMatrix()));
  const ImuSample up{2.0, {1, 2, 9.8}, {0.1, 0.2, 0.3}};
  const ImuSample in_lidar = rotated(up, flat.imu_to_lidar_rotation());
  EXPECT_TRUE(in_lidar.acceleration.isApprox(Eigen::Vector3d(-1, -2, 9.8)));
  EXPECT_TRUE(in_lidar.angular_velocity.isApprox(Eigen::Vector3d(-0.1, -0.2, 0.3)));
  // Nested layout, an IMU turned 90 deg about z in the sensor: its x is the
  // sensor's y, which is the lidar's -y.
  const auto nested = parse_ouster_imu_calibration(R"({"sensor_info": {}, "config_params": {"udp_port_imu": 7503},
      "imu_intrinsics": {"imu_to_sensor_transform": [0,-1,0,0, 1,0,0,0, 0,0,1,0, 0,0,0,1]},
      "lidar_intrinsics": {"lidar_to_sensor_transform": [-1,0,0,0, 0,-1,0,0, 0,0,1,38.195, 0,0,0,1]}})",
                                                   "n.json");
  EXPECT_TRUE((nested.imu_to_lidar_rotation() * Eigen::Vector3d::UnitX()).isApprox(-Eigen::Vector3d::UnitY()));
  // Firmware before 2.2 names no port: the default.
  EXPECT_EQ(parse_ouster_imu_calibration(R"({"imu_to_sensor_transform": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1],
      "lidar_to_sensor_transform": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]})", "o.json").udp_port_imu, 7503);
}

TEST(OusterImu, MetadataErrorsNameTheFileAndTheKey) {
  const auto error = [](const std::string& text) {
    return testing::input_error_of([&] { (void)parse_ouster_imu_calibration(text, "meta.json"); });
  };
  const auto with = [](const std::string& from, const std::string& to) {
    std::string text = kFlat;
    return text.replace(text.find(from), from.size(), to);
  };
  EXPECT_NE(error("{").find("meta.json"), std::string::npos);
  EXPECT_NE(error("{}").find("imu_to_sensor_transform"), std::string::npos);
  EXPECT_NE(error(with("7600", "70000")).find("udp_port_imu"), std::string::npos);
  EXPECT_NE(error(with("\"LEGACY\"", "\"ACCEL32_GYRO32_NMEA\"")).find("ACCEL32_GYRO32_NMEA"), std::string::npos);
  EXPECT_NE(error(with("[1,0,0,6.253", "[2,0,0,6.253")).find("not one"), std::string::npos);
  EXPECT_NE(error(with("0,0,0,1]}", "0,0,1,1]}")).find("last row"), std::string::npos);
  EXPECT_NE(testing::input_error_of([] { (void)read_ouster_imu_calibration("/nonexistent/m.json"); })
                .find("/nonexistent/m.json"), std::string::npos);
}

/// `n` samples at 100 Hz of a still sensor, gravity along +z.
std::vector<ImuSample> still(std::size_t n) {
  std::vector<ImuSample> out;
  for (std::size_t i = 0; i < n; ++i) {
    const double wobble = (i % 2 ? 1.0 : -1.0) * 0.01;  // 0.57 deg/s
    out.push_back({100.0 + 0.01 * static_cast<double>(i), {0.1, -0.2, 9.81}, {wobble, -wobble, 0.0}});
  }
  return out;
}

bool mentions(const std::vector<std::string>& problems, const std::string& word) {
  for (const auto& p : problems) {
    if (p.find(word) != std::string::npos) return true;
  }
  return false;
}

TEST(OusterImu, StatsOfAStillStreamAndTheMistakesTheyName) {
  auto samples = still(101);
  const auto s = imu_stream_stats(samples);
  EXPECT_EQ(s.samples, 101U);
  EXPECT_NEAR(s.rate_hz, 100.0, 1e-6);
  EXPECT_NEAR(s.largest_gap_s, 0.01, 1e-9);
  EXPECT_EQ(s.rest_samples, 101U);
  EXPECT_NEAR(s.gravity_at_rest, Eigen::Vector3d(0.1, -0.2, 9.81).norm(), 1e-12);
  // x and y: 51 of -0.01 and 50 of +0.01 rad/s; z: 0.
  EXPECT_NEAR(s.gyro_noise_dps, std::sqrt(2.0 / 3.0 * (101.0 - 1.0 / 101.0) / 100.0) * 0.01 * 180.0 / kPi, 1e-9);
  EXPECT_TRUE(imu_stream_problems(s).empty()) << imu_stream_problems(s).front();
  EXPECT_EQ(imu_stream_problems(imu_stream_stats({})), std::vector<std::string>{"no IMU samples"});

  auto in_g = samples;
  for (auto& x : in_g) x.acceleration /= kStandardGravity;
  EXPECT_TRUE(mentions(imu_stream_problems(imu_stream_stats(in_g)), "read in g"));
  auto turning_in_dps = samples;  // turning at 30 deg/s, deg/s taken for rad/s
  for (auto& x : turning_in_dps) x.angular_velocity.z() = 30.0;
  const auto t = imu_stream_problems(imu_stream_stats(turning_in_dps));
  EXPECT_TRUE(mentions(t, "deg/s read as rad/s"));
  EXPECT_TRUE(mentions(t, "never still"));
  auto jumbled = samples;
  std::swap(jumbled[10].time, jumbled[11].time);
  jumbled[20].time = jumbled[19].time;
  jumbled.erase(jumbled.begin() + 50, jumbled.begin() + 60);
  const auto j = imu_stream_stats(jumbled);
  EXPECT_EQ(j.backwards_steps, 1U);
  EXPECT_EQ(j.repeated_times, 1U);
  EXPECT_NEAR(j.largest_gap_s, 0.11, 1e-9);
  const auto jp = imu_stream_problems(j);
  EXPECT_TRUE(mentions(jp, "backwards"));
  EXPECT_TRUE(mentions(jp, "repeat"));
  EXPECT_TRUE(mentions(jp, "gap"));
}

struct Capture {
  std::string pcap, metadata;
  std::size_t samples;
  bool still;  ///< false: the sensor moves (the capture comes with poses)
};

TEST(OusterImu, RealCapturesReadOneGAndAStillGyroscope) {
  SALOAM_REQUIRE_SHARED_DATA();
  SALOAM_REQUIRE_OUSTER_PCAPS();
  const std::vector<Capture> captures{
      {"OS-0-32-U1_v2.2.0_1024x10", "OS-0-32-U1_v2.2.0_1024x10", 10, true},
      {"OS-0-128-U1_v2.3.0_1024x10", "OS-0-128-U1_v2.3.0_1024x10", 10, true},
      {"OS-1-128_767798045_1024x10_20230712_120049", "OS-1-128_767798045_1024x10_20230712_120049", 2, true},
      {"OS-1-128_v2.3.0_1024x10_lb_n3", "OS-1-128_v2.3.0_1024x10", 30, false},
      {"OS-1-32-G_v2.1.1_1024x10", "OS-1-32-G_v2.1.1_1024x10", 0, true},  // records no IMU packets
  };
  const auto folder = testing::shared_file("data/ouster_pcaps");
  for (const auto& c : captures) {
    SCOPED_TRACE(c.pcap);
    const auto calibration = read_ouster_imu_calibration(folder / (c.metadata + ".json"));
    EXPECT_EQ(calibration.udp_port_imu, 7503);
    ImuReadCounts counts;
    const auto samples = read_ouster_imu(folder / (c.pcap + ".pcap"), calibration.udp_port_imu, &counts);
    ASSERT_EQ(samples.size(), c.samples);
    EXPECT_EQ(counts.datagrams, c.samples);  // every datagram to the port a 48-byte IMU packet
    if (samples.empty()) continue;
    const auto s = imu_stream_stats(samples);
    EXPECT_GT(s.rate_hz, 90.0);
    EXPECT_LT(s.rate_hz, 130.0);
    EXPECT_EQ(s.backwards_steps + s.repeated_times, 0U);
    // Gyroscopes near 0: at most 3 deg/s still, 7 deg/s on the moving capture.
    EXPECT_LT(s.largest_gyro_rad_s * 180.0 / kPi, c.still ? 3.0 : 7.0);
    if (c.still) {
      EXPECT_EQ(s.rest_samples, s.samples);
      EXPECT_GT(s.gravity_at_rest, 9.9);  // 1.01-1.05 g: gravity and this accelerometer's scale error
      EXPECT_LT(s.gravity_at_rest, 10.3);
      EXPECT_TRUE(imu_stream_problems(s).empty()) << imu_stream_problems(s).front();
    } else {
      // Moving at 2.5 m/s (its poses), the pitch rate swinging by +-5 deg/s: |a| reads 1.09 g, more than the
      // poses' 0.07 g of acceleration explains (vibration?), so only a loose band around gravity.
      EXPECT_GT(s.mean_acceleration_norm, 9.9);
      EXPECT_LT(s.mean_acceleration_norm, 11.3);
    }
    // Up is +z in the IMU frame and, rotated, in the lidar frame.
    const Eigen::Vector3d up = calibration.imu_to_lidar_rotation() * s.mean_acceleration;
    EXPECT_GT(up.z(), 0.95 * kStandardGravity);
    EXPECT_GT(s.mean_acceleration.z(), 0.95 * kStandardGravity);
  }
}

}  // namespace
}  // namespace saloam
