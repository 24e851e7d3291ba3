#pragma once
// What the MCAP reader (mcap.cpp) and writer (mcap_writer.cpp) share: the
// record op codes of the MCAP format (mcap.dev/spec) and its CRC-32.
// Internal to io: nothing outside this module includes it.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace saloam::mcap_records {

inline constexpr std::uint8_t kHeader = 0x01, kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05,
                              kChunk = 0x06, kMessageIndex = 0x07, kChunkIndex = 0x08, kStatistics = 0x0B,
                              kSummaryOffset = 0x0E, kDataEnd = 0x0F;

/// CRC-32 (IEEE 802.3, reflected) of `bytes`, continuing from `crc`.
inline std::uint32_t crc32(std::span<const std::byte> bytes, std::uint32_t crc = 0) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (const std::byte b : bytes) crc = table[(crc ^ static_cast<std::uint8_t>(b)) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

}  // namespace saloam::mcap_records
