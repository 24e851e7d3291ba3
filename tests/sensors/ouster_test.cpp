// Ouster metadata (both layouts), the XYZ lookup, frames by frame id,
// destaggering, and what is refused.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "saloam/core/error.hpp"
#include "saloam/sensors/ouster_frame.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

std::string flat_metadata(const std::string& profile, int beams = 2, int columns = 32) {
  std::vector<int> altitude, azimuth, shift;
  for (int i = 0; i < beams; ++i) {
    altitude.push_back(10 - 20 * i);
    azimuth.push_back(i ? 0 : 90);
    shift.push_back(3 * i);
  }
  return fmt::format(R"({{"prod_line": "OS-1-TEST", "build_rev": "v2.3.0", "lidar_mode": "{}x10",
      "beam_altitude_angles": [{}], "beam_azimuth_angles": [{}], "lidar_origin_to_beam_origin_mm": 10,
      "lidar_to_sensor_transform": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1],
      "data_format": {{"columns_per_frame": {}, "columns_per_packet": 16, "pixels_per_column": {},
                       "pixel_shift_by_row": [{}], "udp_profile_lidar": "{}"}}}})",
                     columns, fmt::join(altitude, ", "), fmt::join(azimuth, ", "), columns, beams,
                     fmt::join(shift, ", "), profile);
}

TEST(OusterMetadata, FlatAndNestedLayouts) {
  const auto flat = parse_ouster_metadata(flat_metadata("RNG19_RFL8_SIG16_NIR16"), "m.json");
  EXPECT_FALSE(flat.nested_layout);
  EXPECT_EQ(flat.profile, OusterProfile::kRng19Rfl8Sig16Nir16);
  EXPECT_EQ(flat.columns_per_frame, 32U);
  EXPECT_EQ(flat.packets_per_frame(), 2U);
  EXPECT_DOUBLE_EQ(flat.beam_to_lidar(0, 3), 10.0);
  const std::string nested = R"({"sensor_info": {"prod_line": "OS-0-32", "build_rev": "v3.0.1", "prod_sn": 992},
    "config_params": {"lidar_mode": "512x20", "udp_port_lidar": 7000},
    "lidar_data_format": {"columns_per_frame": 512, "columns_per_packet": 16, "pixels_per_column": 1,
                          "column_window": [10, 500], "udp_profile_lidar": "LEGACY"},
    "beam_intrinsics": {"beam_altitude_angles": [1.5], "beam_azimuth_angles": [-2],
                        "lidar_origin_to_beam_origin_mm": 27.67,
                        "beam_to_lidar_transform": [1,0,0,27.67, 0,1,0,0, 0,0,1,3, 0,0,0,1]},
    "lidar_intrinsics": {"lidar_to_sensor_transform": [-1,0,0,0, 0,-1,0,0, 0,0,1,36.18, 0,0,0,1]},
    "calibration_status": {}, "imu_intrinsics": {}})";
  const auto m = parse_ouster_metadata(nested, "n.json");
  EXPECT_TRUE(m.nested_layout);
  EXPECT_EQ(m.serial, "992");
  EXPECT_DOUBLE_EQ(m.frequency_hz, 20.0);
  EXPECT_EQ(m.udp_port_lidar, 7000);
  EXPECT_EQ(m.column_window.first, 10U);
  EXPECT_EQ(m.packets_per_frame(), 32U);  // packets 0..31 carry columns 10..500
  EXPECT_DOUBLE_EQ(m.beam_to_lidar(2, 3), 3.0);
  EXPECT_EQ(m.pixel_shift_by_row, std::vector<int>{0});
}

// Issue #53: metadata that would put points anywhere is refused, naming the
// field (an origin of 1e300 mm put the points 1,700 km away).
TEST(OusterMetadata, ValuesThatMovePointsAnywhereAreRefused) {
  const std::string good = flat_metadata("LEGACY");
  const auto error = [](const std::string& text) {
    return testing::input_error_of([&] { (void)parse_ouster_metadata(text, "m.json"); });
  };
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  EXPECT_EQ(error(good), "no error");
  EXPECT_NE(error(replaced("\"lidar_origin_to_beam_origin_mm\": 10", "\"lidar_origin_to_beam_origin_mm\": 1e300"))
                .find("m.json: Ouster metadata: lidar_origin_to_beam_origin_mm"),
            std::string::npos);
  EXPECT_NE(error(replaced("\"beam_altitude_angles\": [10", "\"beam_altitude_angles\": [1e300"))
                .find("beam_altitude_angles[0]"),
            std::string::npos);
  EXPECT_NE(error(replaced("[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]", "[2,0,0,0, 0,2,0,0, 0,0,2,0, 0,0,0,1]"))
                .find("lidar_to_sensor_transform is not a rigid transform"),
            std::string::npos);
  EXPECT_NE(error(replaced("[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]", "[1,0,0,1e9, 0,1,0,0, 0,0,1,0, 0,0,0,1]"))
                .find("lidar_to_sensor_transform"),
            std::string::npos);
}

TEST(OusterMetadata, ErrorsNameTheFileAndTheKey) {
  const auto error = [](const std::string& text) {
    return testing::input_error_of([&] { (void)parse_ouster_metadata(text, "meta.json"); });
  };
  EXPECT_NE(error("{").find("meta.json"), std::string::npos);
  EXPECT_NE(error("{}").find("lidar_mode"), std::string::npos);
  EXPECT_NE(error(flat_metadata("RNG99")).find("RNG99"), std::string::npos);
  std::string short_list = flat_metadata("LEGACY");
  short_list.replace(short_list.find("[10, -10]"), 9, "[10]");
  EXPECT_NE(error(short_list).find("beam_altitude_angles"), std::string::npos);
  std::string bad_columns = flat_metadata("LEGACY");
  bad_columns.replace(bad_columns.find("\"columns_per_packet\": 16"), 24, "\"columns_per_packet\": 5");
  EXPECT_NE(error(bad_columns).find("columns_per_packet"), std::string::npos);
}

TEST(OusterXyz, TheSdkLookup) {
  const auto m = parse_ouster_metadata(flat_metadata("LEGACY"), "m.json");
  const OusterXyzLut lut(m);
  // Row 1: altitude -10 deg, azimuth 0; column 0 looks along +x of the lidar frame.
  const double c = std::cos(-10 * std::numbers::pi / 180), s = std::sin(-10 * std::numbers::pi / 180);
  Eigen::Vector3d p = lut.point(1, 0, 1000.0);
  EXPECT_NEAR(p.x(), 0.010 + (1.0 - 0.010) * c, 1e-9);  // the beam origin 10 mm out along the encoder's direction
  EXPECT_NEAR(p.y(), 0.0, 1e-9);
  EXPECT_NEAR(p.z(), (1.0 - 0.010) * s, 1e-9);
  // Row 0: beam azimuth +90 deg (turned clockwise), altitude +10; column 8 of 32 is a quarter turn on (encoder -90 deg).
  p = lut.point(0, 8, 2000.0);
  const double ca = std::cos(10 * std::numbers::pi / 180);
  EXPECT_NEAR(p.x(), -(2.0 - 0.010) * ca, 1e-9);
  EXPECT_NEAR(p.y(), -0.010, 1e-9);
}

TEST(OusterXyz, DestaggerShiftsEachRow) {
  const std::vector<int> image{1, 2, 3, 4, 5, 6, 7, 8};
  const std::vector<int> shifts{0, 1};
  EXPECT_EQ(destagger<int>(image, 4, shifts), (std::vector<int>{1, 2, 3, 4, 8, 5, 6, 7}));
}

/// A LEGACY packet of frame `frame` carrying columns first..first+15, each valid unless `invalid`.
std::vector<std::uint8_t> legacy_packet(const OusterPacketFormat& format, std::uint16_t frame, std::uint16_t first,
                                        bool invalid = false) {
  std::vector<std::uint8_t> p(format.packet_size(), 0);
  const std::size_t column = p.size() / 16;
  for (std::size_t c = 0; c < 16; ++c) {
    std::uint8_t* col = p.data() + c * column;
    col[0] = static_cast<std::uint8_t>(first + c);  // timestamp
    col[8] = static_cast<std::uint8_t>((first + c) & 0xFF);
    col[9] = static_cast<std::uint8_t>((first + c) >> 8);
    col[10] = static_cast<std::uint8_t>(frame & 0xFF);
    col[11] = static_cast<std::uint8_t>(frame >> 8);
    col[16] = 0xE8;  // range 1000 mm in pixel 0
    col[17] = 0x03;
    if (!invalid) std::fill(col + column - 4, col + column, 0xFF);
  }
  return p;
}

TEST(OusterFrames, ByFrameIdWithLatePacketsDropped) {
  const auto m = parse_ouster_metadata(flat_metadata("LEGACY"), "m.json");
  OusterFrameAssembler assembler(m);
  const auto& f = assembler.format();
  std::vector<OusterScan> done;
  assembler.add(legacy_packet(f, 7, 0), done);
  assembler.add(legacy_packet(f, 8, 0), done);  // frame 7 ends without its second packet
  ASSERT_EQ(done.size(), 1U);
  EXPECT_EQ(done[0].valid_columns, 16U);
  assembler.add(legacy_packet(f, 7, 16), done);  // late
  EXPECT_EQ(assembler.dropped_packets(), 1U);
  assembler.add(legacy_packet(f, 8, 16, true), done);  // invalid columns stay zero; the frame is complete
  ASSERT_EQ(done.size(), 2U);
  EXPECT_EQ(done[1].frame_id, 8U);
  EXPECT_EQ(done[1].valid_columns, 16U);
  EXPECT_EQ(done[1].timestamp[20], 0U);
  assembler.add(std::vector<std::uint8_t>(100, 0), done);
  EXPECT_EQ(assembler.bad_packets(), 1U);
  const OusterXyzLut lut(m);
  const auto cloud = ouster_cloud(done[1], lut, *done[1].first_valid_timestamp(), 255.0F);
  EXPECT_EQ(cloud.size(), 16U);
  EXPECT_TRUE(cloud.has_rings());
  EXPECT_TRUE(cloud.has_times());
  EXPECT_NEAR(cloud.time.back(), 15e-9, 1e-12);
}

}  // namespace
}  // namespace saloam
