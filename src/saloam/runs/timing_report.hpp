#pragma once
// What the runs' timing.json files say of each stage.

#include <vector>

#include <nlohmann/json.hpp>

#include "saloam/core/profiling.hpp"

namespace saloam {

/// {"mean_ms", "median_ms", "max_ms", "total_s"} of per-frame milliseconds.
inline nlohmann::json stage_stats(const std::vector<double>& ms) {
  const Summary s = summarize(ms);
  return {{"mean_ms", s.mean}, {"median_ms", s.median}, {"max_ms", s.max}, {"total_s", s.sum / 1000.0}};
}

/// Frames per second of a frame time [ms]; 0 for no time.
inline double hz(double ms) { return ms > 0 ? 1000.0 / ms : 0.0; }

}  // namespace saloam
