#pragma once
// Small, portable, deterministic random numbers for the simulator: the same
// seed gives the same bytes on every platform and thread count (the standard
// library's distributions are implementation-defined, so we roll our own).

#include <cmath>
#include <cstdint>

#include "saloam/core/hash.hpp"

namespace saloam {

/// xoshiro-like generator built on SplitMix64 (period 2^64, plenty here).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(mix64(seed)) {}
  std::uint64_t next() {
    const std::uint64_t z = mix64(state_);  // mixes state_ + the SplitMix64 increment
    state_ += 0x9E3779B97F4A7C15ull;
    return z;
  }
  /// Uniform in [0, 1).
  double uniform() { return hash_to_unit(next()); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [lo, hi].
  int integer(int lo, int hi) { return lo + static_cast<int>(uniform() * (hi - lo + 1)); }
  bool chance(double p) { return uniform() < p; }
  /// Standard normal (Box-Muller, one value per call).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }
  double normal(double mean, double sigma) { return mean + sigma * normal(); }
  /// Exponential with the given mean.
  double exponential(double mean) { return -mean * std::log(1.0 - uniform()); }

 private:
  std::uint64_t state_;
};

/// Smooth 2D value noise in [0, 1]: random values on an integer lattice,
/// interpolated with a smoothstep. Coordinates in lattice units.
inline double value_noise(std::uint64_t seed, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy);
  const double tx = x - fx, ty = y - fy;
  const double sx = tx * tx * (3.0 - 2.0 * tx), sy = ty * ty * (3.0 - 2.0 * ty);
  auto v = [&](std::int64_t i, std::int64_t j) {
    return hash_to_unit(hash3(seed, static_cast<std::uint64_t>(i), static_cast<std::uint64_t>(j)));
  };
  const double a = v(ix, iy), b = v(ix + 1, iy), c = v(ix, iy + 1), d = v(ix + 1, iy + 1);
  return (a + (b - a) * sx) + ((c + (d - c) * sx) - (a + (b - a) * sx)) * sy;
}

/// Value noise with a wavelength in metres.
inline double noise_at(std::uint64_t seed, double x, double y, double wavelength) {
  return value_noise(seed, x / wavelength, y / wavelength);
}

}  // namespace saloam
