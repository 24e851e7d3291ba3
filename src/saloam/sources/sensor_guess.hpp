#pragma once
// `--sensor auto`: the sensor profile (core/sensor_profile.hpp) a scan most
// likely comes from, judged from one scan by its lasers (lasers.hpp: their
// number and elevations). Each profile gets a score, lower is better, in
// degrees-like units:
//   3   x the degrees of the lasers' span the profile does not cover (1 deg slack)
//   0.3 x the degrees of the profile's field of view beyond the lasers found
//         (weak: lasers that see only sky return nothing)
//   10  x the mean distance [deg] of the lasers found to the profile's nearest
//         laser (only when the lasers were told apart: ring field or storage)
//   a different number of lasers: 4 when counted exactly (ring field,
//         storage order), else 2 per factor of two
// The profile with the lowest score wins; the guess says what was found.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "saloam/core/sensor_profile.hpp"
#include "saloam/core/types.hpp"
#include "saloam/sources/lasers.hpp"

namespace saloam {

struct SensorGuess {
  std::size_t profile = 0;  ///< index of the chosen profile
  FoundLasers lasers;       ///< what the scan showed
  double score = 0.0;
  /// "64 lasers (points stored laser by laser) from +2.0 to -24.9 deg"
  [[nodiscard]] std::string found() const;
};

/// The score of `profile` for `lasers` (see above).
double sensor_score(const SensorProfile& profile, const FoundLasers& lasers);

/// `profile` cut down to the lasers found, for scans that keep only some of
/// its lasers (a simulated HDL-64E with --beams 32 or 16, a driver set to
/// every 2nd laser): when the lasers were counted exactly (ring field or
/// storage order) and are at most half of the profile's, each found laser's
/// nearest laser of the profile, top first. nullopt otherwise, or when two
/// found lasers have the same nearest one.
std::optional<SensorProfile> laser_subset(const SensorProfile& profile, const FoundLasers& lasers);

/// The best of `profiles` (not empty) for `scan`; ConfigError when `profiles` is empty.
SensorGuess guess_sensor(const LabelledCloud& scan, const std::vector<SensorProfile>& profiles);

}  // namespace saloam
