#pragma once
// Content digests of files (a saved map's, docs/map_format.md).

#include <cstdint>
#include <string_view>

namespace saloam {

/// FNV-1a, 64 bits, of `bytes`. Fast and not cryptographic: it finds a file
/// cut, changed or replaced by accident or by another run, not one forged on
/// purpose.
constexpr std::uint64_t fnv1a64(std::string_view bytes) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (const char c : bytes) {
    h ^= static_cast<std::uint8_t>(c);
    h *= 0x100000001b3ull;
  }
  return h;
}

}  // namespace saloam
