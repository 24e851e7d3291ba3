#pragma once
// Ouster lidar packets, bytes in, values out: a pure decoder (no I/O) that a
// capture reader and a live UDP socket both feed. Layouts as Ouster's
// "Sensor Data" documentation gives them, bit for bit as the manufacturer's
// SDK reads them (ouster-sdk, ouster_core/src/parsing.cpp; checked against
// its digests of real captures, tests/sensors/ouster_digest_test.cpp):
//
//   LEGACY                     no packet header or footer; per column a
//                              16-byte header (timestamp u64 [ns],
//                              measurement id u16, frame id u16, encoder
//                              count u32), 12 bytes per pixel, a 4-byte
//                              footer (status u32: bit 0 = valid)
//   every other profile        a 32-byte packet header (packet type u16,
//                              frame id u16, init id 24 bits, serial 40
//                              bits; FuSa: frame id u32 at byte 4), per
//                              column a 12-byte header (timestamp u64,
//                              measurement id u16, status u16), a 32-byte
//                              packet footer
//
// Pixel fields (bit offset, width, left shift; little-endian words):
//   LEGACY         RANGE 0/20, FLAGS 28/4, REFLECTIVITY 32/8, SIGNAL 48/16, NEAR_IR 64/16
//   RNG19 single   RANGE 0/19, FLAGS 19/5, REFLECTIVITY 32/8, SIGNAL 48/16, NEAR_IR 64/16, WINDOW 88/8
//   RNG19 dual     RANGE 0/19, FLAGS 19/5, REFLECTIVITY 24/8, RANGE2 32/19, FLAGS2 51/5,
//                  REFLECTIVITY2 56/8, SIGNAL 64/16, SIGNAL2 80/16, NEAR_IR 96/16, WINDOW 120/8
//   RNG15 (low bandwidth)  RANGE 0/15 <<3 [mm, 8 mm steps], FLAGS 15/1, REFLECTIVITY 16/8, NEAR_IR 24/8 <<4
//   RNG15 dual     as RNG15, NEAR_IR 24/8 <<4, RANGE2 32/15 <<3, FLAGS2 47/1, REFLECTIVITY2 48/8, WINDOW 56/8
// and the raw 32-bit words RAW32_WORD1.. of each pixel. Ranges are [mm];
// each field has the integer type of its width (1, 2 or 4 bytes), which is
// what the digests hash. Reflectivity is 0..255 (calibrated, 100 = a white
// Lambertian target at its range), signal and near-IR photon counts.
//
// Frames: packets carry columns by measurement id (0 .. columns_per_frame-1,
// the encoder's column) and a frame id; OusterFrameAssembler (ouster_frame.hpp)
// gathers them. Nothing here trusts the bytes: a packet of another size than
// the metadata's is refused by check(), and every read stays inside it.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/sensors/ouster_metadata.hpp"

namespace saloam {

enum class OusterField : std::uint8_t {
  kRange,
  kRange2,
  kSignal,
  kSignal2,
  kReflectivity,
  kReflectivity2,
  kNearIr,
  kFlags,
  kFlags2,
  kWindow,
  kRaw32Word1,
  kRaw32Word2,
  kRaw32Word3,
  kRaw32Word4,
};

/// "RANGE", "REFLECTIVITY2", "RAW32_WORD1", ... (the SDK's names).
[[nodiscard]] std::string_view ouster_field_name(OusterField field);

/// Where a field sits in a pixel.
struct OusterFieldLayout {
  OusterField field = OusterField::kRange;
  std::uint16_t bit_offset = 0;
  std::uint8_t bits = 0;
  std::uint8_t upshift = 0;  ///< the value is stored without its low bits (low-bandwidth profiles)
  std::uint8_t bytes = 4;    ///< the field's integer type: 1, 2 or 4 bytes
  [[nodiscard]] bool raw_word() const { return field >= OusterField::kRaw32Word1; }
};

class OusterPacketFormat {
 public:
  explicit OusterPacketFormat(const OusterMetadata& metadata);

  [[nodiscard]] OusterProfile profile() const { return profile_; }
  [[nodiscard]] std::size_t packet_size() const { return packet_size_; }
  [[nodiscard]] std::uint32_t columns_per_packet() const { return columns_per_packet_; }
  [[nodiscard]] std::uint32_t pixels_per_column() const { return pixels_per_column_; }
  /// The profile's fields, in the SDK's order (raw words last).
  [[nodiscard]] const std::vector<OusterFieldLayout>& fields() const { return fields_; }
  [[nodiscard]] const OusterFieldLayout* layout(OusterField field) const;

  /// Empty when `packet` can be decoded with this format, else why not.
  [[nodiscard]] std::string check(std::span<const std::uint8_t> packet) const;

  // Packet header (LEGACY: the first column's frame id; init id 0).
  [[nodiscard]] std::uint32_t frame_id(std::span<const std::uint8_t> packet) const;
  [[nodiscard]] std::uint32_t init_id(std::span<const std::uint8_t> packet) const;
  /// b - a for frame ids that wrap at 2^16 (2^32 with the FuSa header): > 0 when b is later.
  [[nodiscard]] std::int64_t frame_id_difference(std::uint32_t a, std::uint32_t b) const;

  // Column c's header (c < columns_per_packet), as the SDK returns them.
  [[nodiscard]] std::uint64_t col_timestamp(std::span<const std::uint8_t> packet, std::uint32_t c) const;
  [[nodiscard]] std::uint16_t col_measurement_id(std::span<const std::uint8_t> packet, std::uint32_t c) const;
  [[nodiscard]] std::uint32_t col_status(std::span<const std::uint8_t> packet, std::uint32_t c) const;
  /// LEGACY only (0 otherwise).
  [[nodiscard]] std::uint32_t col_encoder(std::span<const std::uint8_t> packet, std::uint32_t c) const;
  /// LEGACY only (0 otherwise).
  [[nodiscard]] std::uint16_t col_frame_id(std::span<const std::uint8_t> packet, std::uint32_t c) const;

  /// Field `f` of pixel `px` of column `c`.
  [[nodiscard]] std::uint32_t pixel(std::span<const std::uint8_t> packet, std::uint32_t c, std::uint32_t px,
                                    const OusterFieldLayout& f) const;

 private:
  [[nodiscard]] std::size_t column_start(std::uint32_t c) const { return packet_header_ + c * column_size_; }

  OusterProfile profile_;
  bool legacy_ = false;
  bool fusa_ = false;
  std::uint32_t columns_per_packet_ = 0;
  std::uint32_t pixels_per_column_ = 0;
  std::size_t packet_header_ = 0;
  std::size_t column_header_ = 0;
  std::size_t pixel_size_ = 0;
  std::size_t column_size_ = 0;
  std::size_t packet_size_ = 0;
  std::vector<OusterFieldLayout> fields_;
};

}  // namespace saloam
