// Velodyne packets: encoded and decoded again, the calibration file, the
// sweeps cut behind the sensor, packets refused.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "saloam/core/error.hpp"
#include "saloam/sensors/velodyne_frame.hpp"
#include "saloam/sensors/velodyne_packet.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

/// Twelve firings from `azimuth` [0.01 deg] on, `step` apart, every channel at `distance` counts.
std::array<VelodyneFiring, 12> firings(int azimuth, int step, std::uint16_t distance, bool hdl64e = false) {
  std::array<VelodyneFiring, 12> out{};
  for (std::size_t b = 0; b < 12; ++b) {
    const std::size_t firing = hdl64e ? b / 2 : b;
    out[b].azimuth = static_cast<std::uint16_t>((azimuth + step * static_cast<int>(firing)) % 36000);
    out[b].lower = hdl64e && b % 2 == 1;
    out[b].distance.fill(distance);
    for (std::size_t ch = 0; ch < 32; ++ch) out[b].intensity[ch] = static_cast<std::uint8_t>(ch * 7);
  }
  return out;
}

TEST(VelodynePacket, AnHdl32eFiringLiesAlongItsAzimuthAndElevation) {
  const auto packet = encode_velodyne_packet(VelodyneModel::kHdl32e, firings(9000, 20, 5000), 123456);
  ASSERT_EQ(packet.size(), kVelodynePacketBytes);
  EXPECT_EQ(check_velodyne_packet(packet), "");
  EXPECT_EQ(velodyne_model_of(packet), VelodyneModel::kHdl32e);
  EXPECT_EQ(velodyne_tail(packet).timestamp_us, 123456U);
  const VelodyneDecoder decoder(VelodyneModel::kHdl32e, *nominal_velodyne_calibration(VelodyneModel::kHdl32e));
  std::vector<VelodyneReturn> returns;
  decoder.decode(packet, returns);
  ASSERT_EQ(returns.size(), 12U * 32U);
  // Block 0, channel 0: 10 m at azimuth 90 deg (clockwise from the front: to the right), -30.67 deg down.
  const auto& r = returns.front();
  EXPECT_NEAR(r.point.x(), 0.0, 1e-5);
  EXPECT_NEAR(r.point.y(), -10.0 * std::cos(-30.67 * kDeg), 1e-5);
  EXPECT_NEAR(r.point.z(), 10.0 * std::sin(-30.67 * kDeg), 1e-5);
  EXPECT_EQ(r.ring, 31);  // the lowest laser
  EXPECT_EQ(returns[31].ring, 0);  // channel 31: +10.67 deg, the highest
  EXPECT_FLOAT_EQ(returns[1].intensity, 7.0F);
  // Block 3's channel 5 fires 3 x 46.08 + 2 x 1.152 us after the timestamp.
  EXPECT_NEAR(returns[3 * 32 + 5].time_offset, (3 * 46.08 + 2 * 1.152) * 1e-6, 1e-12);
}

TEST(VelodynePacket, Vlp16LasersTurnWithTheirFiringTime) {
  const auto packet = encode_velodyne_packet(VelodyneModel::kVlp16, firings(0, 40, 2500), 0);
  EXPECT_EQ(velodyne_model_of(packet), VelodyneModel::kVlp16);
  const VelodyneDecoder decoder(VelodyneModel::kVlp16, *nominal_velodyne_calibration(VelodyneModel::kVlp16));
  std::vector<VelodyneReturn> returns;
  decoder.decode(packet, returns);
  ASSERT_EQ(returns.size(), 12U * 32U);
  // Channel 16 is the second firing sequence: half way to the next block's azimuth (0.2 deg).
  const auto& second = returns[16];
  const double azimuth = -std::atan2(second.point.y(), second.point.x()) / kDeg;
  EXPECT_NEAR(azimuth, 0.2, 1e-4);
  EXPECT_NEAR(second.time_offset, 55.296e-6, 1e-12);
  EXPECT_EQ(returns[0].ring, 15);  // channel 0: -15 deg
  EXPECT_EQ(returns[1].ring, 7);   // channel 1: +1 deg
}

TEST(VelodynePacket, Hdl64eNeedsLowerBlocksAndItsCalibration) {
  EXPECT_FALSE(nominal_velodyne_calibration(VelodyneModel::kHdl64e));
  VelodyneCalibration calibration;
  for (int i = 0; i < 64; ++i) {
    VelodyneLaser l;
    l.vert_correction = (2.0 - 0.4 * i) * kDeg;
    l.rot_correction = (i % 2 ? 1.0 : -1.0) * kDeg;
    l.dist_correction = 0.01 * (i % 5);
    l.dist_correction_x = l.dist_correction_y = l.dist_correction;
    calibration.lasers.push_back(l);
  }
  testing::TempDir dir;
  const auto parsed = parse_velodyne_calibration(velodyne_calibration_yaml(calibration), dir / "c.yaml");
  ASSERT_EQ(parsed.lasers.size(), 64U);
  for (std::size_t i = 0; i < 64; ++i) {
    EXPECT_DOUBLE_EQ(parsed.lasers[i].vert_correction, calibration.lasers[i].vert_correction);
    EXPECT_DOUBLE_EQ(parsed.lasers[i].rot_correction, calibration.lasers[i].rot_correction);
    EXPECT_DOUBLE_EQ(parsed.lasers[i].dist_correction_x, calibration.lasers[i].dist_correction);
  }
  const auto packet = encode_velodyne_packet(VelodyneModel::kHdl64e, firings(0, 17, 10000, true), 0);
  EXPECT_EQ(velodyne_model_of(packet), VelodyneModel::kHdl64e);
  const VelodyneDecoder decoder(VelodyneModel::kHdl64e, parsed);
  std::vector<VelodyneReturn> returns;
  decoder.decode(packet, returns);
  ASSERT_EQ(returns.size(), 12U * 32U);
  EXPECT_EQ(returns[32].ring, 32);  // block 1 is a lower block: lasers 32..63
  // Laser 1: 20 m + 1 cm, rot_correction +1 deg turns it to azimuth -1 deg (left).
  const auto& r = returns[1];
  EXPECT_NEAR(r.point.norm(), 20.01, 2e-3);
  EXPECT_GT(r.point.y(), 0.0F);
  EXPECT_NEAR(std::atan2(r.point.y(), r.point.x()) / kDeg, 1.0, 0.05);
}

TEST(VelodynePacket, CalibrationErrorsNameTheFile) {
  EXPECT_NE(testing::input_error_of([] { (void)parse_velodyne_calibration("lasers: 3", "calib.yaml"); })
                .find("calib.yaml"),
            std::string::npos);
  EXPECT_NE(testing::input_error_of([] {
              (void)parse_velodyne_calibration("lasers:\n- {laser_id: 0}\n- {laser_id: 0}\n", "c.yaml");
            }).find("twice"),
            std::string::npos);
  EXPECT_NE(testing::input_error_of([] { (void)parse_velodyne_calibration("lasers: [{laser_id: 5}]", "c.yaml"); })
                .find("laser_id"),
            std::string::npos);
  EXPECT_NE(testing::input_error_of([] { (void)parse_velodyne_calibration("{", "bad.yaml"); }).find("bad.yaml"),
            std::string::npos);
}

// Issue #53: corrections that would put points anywhere (1e300 put them
// 1,700 km away) are refused, naming the laser and the key.
TEST(VelodynePacket, CalibrationValuesOutOfRangeAreRefused) {
  const auto error = [](const std::string& laser) {
    return testing::input_error_of([&] { (void)parse_velodyne_calibration("lasers:\n- {laser_id: 0, " + laser + "}\n", "c.yaml"); });
  };
  EXPECT_NE(error("vert_correction: .nan").find("c.yaml: Velodyne calibration: laser entry 0: \"vert_correction\""),
            std::string::npos);
  EXPECT_NE(error("dist_correction: 1e300").find("\"dist_correction\""), std::string::npos);
  EXPECT_NE(error("rot_correction: 7").find("\"rot_correction\""), std::string::npos);
  EXPECT_NE(error("horiz_offset_correction: -.inf").find("horiz_offset_correction"), std::string::npos);
  EXPECT_EQ(error("rot_correction: -0.1, vert_correction: 0.2, dist_correction: 1.4"), "no error");
}

TEST(VelodynePacket, CorruptPacketsAreRefused) {
  auto packet = encode_velodyne_packet(VelodyneModel::kVlp16, firings(0, 40, 100), 0);
  EXPECT_NE(check_velodyne_packet(std::span(packet).first(1000)), "");
  packet[300] = 0x12;  // block 3's flag
  EXPECT_NE(check_velodyne_packet(packet).find("block 3"), std::string::npos);
  auto far = encode_velodyne_packet(VelodyneModel::kVlp16, firings(0, 40, 100), 0);
  far[2] = 0xFF;
  far[3] = 0xFF;  // azimuth 655.35 deg
  EXPECT_NE(check_velodyne_packet(far), "");
  VelodyneFrameAssembler assembler(VelodyneDecoder(VelodyneModel::kVlp16, *nominal_velodyne_calibration(VelodyneModel::kVlp16)));
  std::vector<VelodyneFrame> frames;
  assembler.add(packet, frames);
  assembler.add(far, frames);
  EXPECT_EQ(assembler.bad_packets(), 2U);
  EXPECT_FALSE(assembler.finish());
}

TEST(VelodyneFrames, SweepsEndBehindTheSensor) {
  VelodyneFrameAssembler assembler(VelodyneDecoder(VelodyneModel::kHdl32e, *nominal_velodyne_calibration(VelodyneModel::kHdl32e)));
  std::vector<VelodyneFrame> frames;
  // 12 blocks of 1 deg per packet from 170 deg: block 10 of the first packet is at 180 deg.
  std::uint32_t stamp = 3599999000U;  // a microsecond count that passes the top of the hour
  for (int p = 0; p < 40; ++p) {
    const int azimuth = (17000 + 1200 * p) % 36000;
    assembler.add(encode_velodyne_packet(VelodyneModel::kHdl32e, firings(azimuth, 100, 1000), stamp), frames);
    stamp = (stamp + 553) % 3600000000U;
  }
  ASSERT_EQ(frames.size(), 2U);  // 10 deg before the first cut, then one whole turn
  EXPECT_EQ(frames[0].cloud.size(), 10U * 32U);
  EXPECT_EQ(frames[1].cloud.size(), 360U * 32U);
  auto last = assembler.finish();
  ASSERT_TRUE(last);
  // Turns: 480 blocks of 1 deg; 10 in the first frame, 360 in the second, 110 in the third.
  EXPECT_EQ(last->cloud.size(), 110U * 32U);
  EXPECT_EQ(assembler.frames_begun(), 3U);
  EXPECT_EQ(assembler.missing_packets(), 0U);
  // Times run on across the top of the hour.
  EXPECT_GT(last->time, frames[0].time);
  EXPECT_NEAR(last->time - frames[0].time, 370 * 46.08e-6, 5e-6);
}

}  // namespace
}  // namespace saloam

namespace saloam {
namespace {

TEST(VelodyneFrames, GapsInTheTimestampsCountAsMissingPackets) {
  VelodyneCalibration calibration;
  calibration.lasers.resize(64);
  for (const bool hdl64e : {false, true}) {
    SCOPED_TRACE(hdl64e ? "HDL-64E" : "HDL-32E");
    const VelodyneModel model = hdl64e ? VelodyneModel::kHdl64e : VelodyneModel::kHdl32e;
    VelodyneFrameAssembler assembler(
        hdl64e ? VelodyneDecoder(model, calibration) : VelodyneDecoder(model, *nominal_velodyne_calibration(model)));
    const double period_us = hdl64e ? 6 * 48.0 : 12 * 46.08;  // a packet's span
    std::vector<VelodyneFrame> frames;
    for (int p = 0; p < 10; ++p) {
      if (p == 4 || p == 7 || p == 8) continue;  // three packets lost
      const auto stamp = static_cast<std::uint32_t>(std::lround(p * period_us));
      assembler.add(encode_velodyne_packet(model, firings(100 * p, 5, 1000, hdl64e), stamp), frames);
    }
    EXPECT_EQ(assembler.missing_packets(), 3U);
  }
}

}  // namespace
}  // namespace saloam
