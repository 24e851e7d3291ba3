#pragma once
// Deterministic integer hashing: the same input gives the same bits on every
// platform and thread count (for draws that must not depend on a generator's
// state, e.g. which pairs an evaluation samples, or simulated noise).

#include <cstdint>

namespace saloam {

/// SplitMix64 finaliser: a good 64-bit mixing function.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// Hash of several integers (order matters).
constexpr std::uint64_t hash_combine(std::uint64_t a, std::uint64_t b) { return mix64(a ^ mix64(b + 0x632BE59BD9B4E019ull)); }
constexpr std::uint64_t hash3(std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  return hash_combine(hash_combine(a, b), c);
}

/// Cheap finaliser for hash-table keys: folds the high bits into the low
/// ones, which open-addressing tables index their buckets by.
constexpr std::uint64_t fold_to_low_bits(std::uint64_t h) {
  h ^= h >> 29;
  h *= 0xbf58476d1ce4e5b9ull;
  return h ^ (h >> 32);
}

/// Uniform double in [0, 1) from a hash.
inline double hash_to_unit(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

}  // namespace saloam
