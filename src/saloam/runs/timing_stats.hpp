#pragma once
// Summary statistics of per-frame timings, shared by the runs' timing reports.

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

#include <nlohmann/json.hpp>

namespace saloam {

/// The upper median (element n/2 in sorted order); 0 for no values.
inline double median_of(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

/// The mean; 0 for no values.
inline double mean_of(const std::vector<double>& values) {
  return values.empty() ? 0.0 : std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
}

/// {"mean_ms", "median_ms", "max_ms", "total_s"} of per-frame milliseconds.
inline nlohmann::json stage_stats(const std::vector<double>& ms) {
  return {{"mean_ms", mean_of(ms)},
          {"median_ms", median_of(ms)},
          {"max_ms", ms.empty() ? 0.0 : *std::max_element(ms.begin(), ms.end())},
          {"total_s", std::accumulate(ms.begin(), ms.end(), 0.0) / 1000.0}};
}

}  // namespace saloam
