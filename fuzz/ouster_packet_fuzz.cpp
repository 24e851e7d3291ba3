// Ouster lidar packets (sensors/ouster_*.hpp): the first byte picks the
// packet profile and 32 or 128 pixels per column (1024 columns, 16 per
// packet); the rest is a run of packets, each behind a 2-byte little-endian
// length, fed to the frame assembler, and every frame it finishes turned
// into points. With the first byte's top bit set the rest is metadata JSON
// instead (parse_ouster_metadata).

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "fuzz_support.hpp"
#include "saloam/sensors/ouster_frame.hpp"

namespace {

saloam::OusterMetadata metadata(std::uint8_t choice) {
  using namespace saloam;
  static const OusterProfile kProfiles[] = {OusterProfile::kLegacy, OusterProfile::kRng19Rfl8Sig16Nir16,
                                            OusterProfile::kRng19Rfl8Sig16Nir16Dual, OusterProfile::kRng15Rfl8Nir8,
                                            OusterProfile::kRng15Rfl8Nir8Dual, OusterProfile::kFusaRng15Rfl8Nir8Dual};
  OusterMetadata m;
  m.profile = kProfiles[choice % 6];
  m.pixels_per_column = (choice / 6) % 2 ? 128 : 32;
  m.columns_per_frame = 1024;
  m.columns_per_packet = 16;
  m.column_window = {0, 1023};
  m.lidar_mode = "1024x10";
  m.pixel_shift_by_row.assign(m.pixels_per_column, 0);
  for (std::uint32_t r = 0; r < m.pixels_per_column; ++r) {
    m.beam_altitude_angles.push_back(20.0 - 0.3 * r);
    m.beam_azimuth_angles.push_back(r % 4 - 1.5);
    m.pixel_shift_by_row[r] = static_cast<int>(r % 4) * 8;
  }
  m.lidar_origin_to_beam_origin_mm = 15.8;
  m.beam_to_lidar(0, 3) = 15.8;
  m.lidar_to_sensor(0, 0) = m.lidar_to_sensor(1, 1) = -1;
  m.lidar_to_sensor(2, 3) = 36.18;
  return m;
}

void check_frame(const saloam::OusterScan& scan, const saloam::OusterXyzLut& lut) {
  SALOAM_FUZZ_CHECK(scan.timestamp.size() == scan.width && scan.status.size() == scan.width);
  SALOAM_FUZZ_CHECK(scan.valid_columns <= scan.width);
  for (const auto& [field, values] : scan.fields) SALOAM_FUZZ_CHECK(values.size() == std::size_t{scan.width} * scan.height);
  const auto cloud = saloam::ouster_cloud(scan, lut, scan.first_valid_timestamp().value_or(0), 255.0F);
  SALOAM_FUZZ_CHECK(cloud.has_rings() || cloud.empty());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    // LEGACY's 20-bit ranges reach 1048.575 m (19 bits: 524 m; 15 bits << 3: 262 m).
    SALOAM_FUZZ_CHECK(cloud.points[i].allFinite() && cloud.points[i].norm() < 1100.0F);
    SALOAM_FUZZ_CHECK(cloud.ring[i] < scan.height && cloud.remission[i] >= 0.0F && cloud.remission[i] <= 1.0F);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  if (size == 0) return 0;
  if (data[0] & 0x80) {
    const std::filesystem::path file = "metadata.json";
    try {
      const OusterMetadata m = parse_ouster_metadata(fuzz::as_text(data + 1, size - 1), file);
      SALOAM_FUZZ_CHECK(m.beam_altitude_angles.size() == m.pixels_per_column);
      SALOAM_FUZZ_CHECK(m.columns_per_frame % m.columns_per_packet == 0 && m.packets_per_frame() >= 1);
      (void)OusterXyzLut(m);
    } catch (const InputError& e) {
      fuzz::check_names_input(e, file);
    }
    return 0;
  }
  // The 12 formats and their XYZ lookups, made once (a 1024 x 128 lookup takes longer than decoding).
  static std::vector<std::pair<OusterMetadata, OusterXyzLut>> formats;
  if (formats.empty()) {
    for (std::uint8_t i = 0; i < 12; ++i) {
      OusterMetadata m = metadata(i);
      OusterXyzLut lut(m);
      formats.emplace_back(std::move(m), std::move(lut));
    }
  }
  const auto& [m, lut] = formats[data[0] % 12];
  OusterFrameAssembler assembler(m);
  std::vector<OusterScan> frames;
  for (std::size_t at = 1; at + 2 <= size;) {
    const std::size_t n = std::min<std::size_t>(data[at] | (data[at + 1] << 8), size - at - 2);
    assembler.add({data + at + 2, n}, frames);
    at += 2 + n;
  }
  if (auto last = assembler.finish()) frames.push_back(std::move(*last));
  for (const auto& frame : frames) check_frame(frame, lut);
  return 0;
}
