#include "saloam/sensors/ouster_packet.hpp"

#include <algorithm>
#include <array>

#include <fmt/format.h>

namespace saloam {
namespace {

constexpr std::array<std::string_view, 14> kFieldNames{
    "RANGE",   "RANGE2", "SIGNAL", "SIGNAL2",     "REFLECTIVITY", "REFLECTIVITY2", "NEAR_IR",
    "FLAGS",   "FLAGS2", "WINDOW", "RAW32_WORD1", "RAW32_WORD2",  "RAW32_WORD3",   "RAW32_WORD4"};

OusterFieldLayout field(OusterField f, int bit_offset, int bits, int upshift = 0) {
  const int needed = bits + upshift;
  const int bytes = needed <= 8 ? 1 : needed <= 16 ? 2 : 4;
  return {f, static_cast<std::uint16_t>(bit_offset), static_cast<std::uint8_t>(bits),
          static_cast<std::uint8_t>(upshift), static_cast<std::uint8_t>(bytes)};
}

using F = OusterField;

std::vector<OusterFieldLayout> raw_words(int n) {
  std::vector<OusterFieldLayout> out;
  for (int i = 0; i < n; ++i) out.push_back(field(static_cast<F>(static_cast<int>(F::kRaw32Word1) + i), 32 * i, 32));
  return out;
}

/// The pixel fields and the pixel size [bytes] of a profile.
std::pair<std::vector<OusterFieldLayout>, std::size_t> profile_fields(OusterProfile profile) {
  std::vector<OusterFieldLayout> fields;
  std::size_t size = 0;
  switch (profile) {
    case OusterProfile::kLegacy:
      fields = {field(F::kRange, 0, 20), field(F::kFlags, 28, 4), field(F::kReflectivity, 32, 8),
                field(F::kSignal, 48, 16), field(F::kNearIr, 64, 16)};
      size = 12;
      break;
    case OusterProfile::kRng19Rfl8Sig16Nir16:
      fields = {field(F::kRange, 0, 19),  field(F::kFlags, 19, 5),   field(F::kReflectivity, 32, 8),
                field(F::kSignal, 48, 16), field(F::kNearIr, 64, 16), field(F::kWindow, 88, 8)};
      size = 12;
      break;
    case OusterProfile::kRng19Rfl8Sig16Nir16Dual:
      fields = {field(F::kRange, 0, 19),         field(F::kFlags, 19, 5),    field(F::kReflectivity, 24, 8),
                field(F::kRange2, 32, 19),       field(F::kFlags2, 51, 5),   field(F::kReflectivity2, 56, 8),
                field(F::kSignal, 64, 16),       field(F::kSignal2, 80, 16), field(F::kNearIr, 96, 16),
                field(F::kWindow, 120, 8)};
      size = 16;
      break;
    case OusterProfile::kRng15Rfl8Nir8:
      fields = {field(F::kRange, 0, 15, 3), field(F::kFlags, 15, 1), field(F::kReflectivity, 16, 8),
                field(F::kNearIr, 24, 8, 4)};
      size = 4;
      break;
    case OusterProfile::kRng15Rfl8Nir8Dual:
    case OusterProfile::kFusaRng15Rfl8Nir8Dual:
      fields = {field(F::kRange, 0, 15, 3),  field(F::kFlags, 15, 1),  field(F::kReflectivity, 16, 8),
                field(F::kNearIr, 24, 8, 4), field(F::kRange2, 32, 15, 3), field(F::kFlags2, 47, 1),
                field(F::kReflectivity2, 48, 8), field(F::kWindow, 56, 8)};
      size = 8;
      break;
  }
  const auto words = raw_words(static_cast<int>(std::min<std::size_t>(size / 4, 4)));
  fields.insert(fields.end(), words.begin(), words.end());
  return {fields, size};
}

/// `n` little-endian bytes at `at` (n <= 8).
std::uint64_t read_le(std::span<const std::uint8_t> b, std::size_t at, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i) v |= std::uint64_t{b[at + i]} << (8 * i);
  return v;
}

}  // namespace

std::string_view ouster_field_name(OusterField f) { return kFieldNames[static_cast<std::size_t>(f)]; }

OusterPacketFormat::OusterPacketFormat(const OusterMetadata& m)
    : profile_(m.profile),
      legacy_(m.profile == OusterProfile::kLegacy),
      fusa_(m.profile == OusterProfile::kFusaRng15Rfl8Nir8Dual),
      columns_per_packet_(m.columns_per_packet),
      pixels_per_column_(m.pixels_per_column) {
  auto [fields, pixel_size] = profile_fields(profile_);
  fields_ = std::move(fields);
  pixel_size_ = pixel_size;
  packet_header_ = legacy_ ? 0 : 32;
  column_header_ = legacy_ ? 16 : 12;
  const std::size_t column_footer = legacy_ ? 4 : 0;
  const std::size_t packet_footer = legacy_ ? 0 : 32;
  column_size_ = column_header_ + pixels_per_column_ * pixel_size_ + column_footer;
  packet_size_ = packet_header_ + columns_per_packet_ * column_size_ + packet_footer;
}

const OusterFieldLayout* OusterPacketFormat::layout(OusterField f) const {
  const auto it = std::find_if(fields_.begin(), fields_.end(), [f](const auto& l) { return l.field == f; });
  return it == fields_.end() ? nullptr : &*it;
}

std::string OusterPacketFormat::check(std::span<const std::uint8_t> packet) const {
  if (packet.size() == packet_size_) return {};
  return fmt::format("lidar packet of {} bytes, but the metadata's {} profile with {} columns of {} pixels makes {}",
                     packet.size(), ouster_profile_name(profile_), columns_per_packet_, pixels_per_column_,
                     packet_size_);
}

std::uint32_t OusterPacketFormat::frame_id(std::span<const std::uint8_t> p) const {
  if (legacy_) return col_frame_id(p, 0);
  if (fusa_) return static_cast<std::uint32_t>(read_le(p, 4, 4));
  return static_cast<std::uint32_t>(read_le(p, 2, 2));
}

std::uint32_t OusterPacketFormat::init_id(std::span<const std::uint8_t> p) const {
  if (legacy_) return 0;
  return static_cast<std::uint32_t>(read_le(p, fusa_ ? 1 : 4, 3));
}

std::int64_t OusterPacketFormat::frame_id_difference(std::uint32_t a, std::uint32_t b) const {
  if (fusa_) return static_cast<std::int64_t>(static_cast<std::int32_t>(b - a));
  return static_cast<std::int64_t>(static_cast<std::int16_t>(static_cast<std::uint16_t>(b - a)));
}

std::uint64_t OusterPacketFormat::col_timestamp(std::span<const std::uint8_t> p, std::uint32_t c) const {
  return read_le(p, column_start(c), 8);
}

std::uint16_t OusterPacketFormat::col_measurement_id(std::span<const std::uint8_t> p, std::uint32_t c) const {
  return static_cast<std::uint16_t>(read_le(p, column_start(c) + 8, 2));
}

std::uint32_t OusterPacketFormat::col_status(std::span<const std::uint8_t> p, std::uint32_t c) const {
  if (legacy_) return static_cast<std::uint32_t>(read_le(p, column_start(c) + column_size_ - 4, 4));
  return static_cast<std::uint32_t>(read_le(p, column_start(c) + 10, 2));
}

std::uint32_t OusterPacketFormat::col_encoder(std::span<const std::uint8_t> p, std::uint32_t c) const {
  return legacy_ ? static_cast<std::uint32_t>(read_le(p, column_start(c) + 12, 4)) : 0;
}

std::uint16_t OusterPacketFormat::col_frame_id(std::span<const std::uint8_t> p, std::uint32_t c) const {
  return legacy_ ? static_cast<std::uint16_t>(read_le(p, column_start(c) + 10, 2)) : 0;
}

std::uint32_t OusterPacketFormat::pixel(std::span<const std::uint8_t> p, std::uint32_t c, std::uint32_t px,
                                        const OusterFieldLayout& f) const {
  const std::size_t at = column_start(c) + column_header_ + px * pixel_size_ + f.bit_offset / 8;
  const unsigned shift = f.bit_offset % 8;
  const std::size_t n = (shift + f.bits + 7) / 8;
  const std::uint64_t mask = (std::uint64_t{1} << f.bits) - 1;
  return static_cast<std::uint32_t>(((read_le(p, at, n) >> shift) & mask) << f.upshift);
}

}  // namespace saloam
