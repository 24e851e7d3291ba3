#include "saloam/slam/loop_candidates.hpp"

#include <algorithm>

namespace saloam {

CandidateGate CandidateGate::from_config(const LoopClosureConfig& config) {
  CandidateGate gate;
  gate.sigma = config.sigma;
  gate.delta_min = config.delta_min;
  gate.delta_max = config.delta_max;
  gate.exclude_recent_distance = config.exclude_recent_distance;
  gate.max_candidates = static_cast<std::size_t>(std::max(0, config.num_candidates));
  return gate;
}

double search_radius(const CandidateGate& gate, double travelled) {
  return std::max(gate.delta_min, std::min(gate.delta_max, gate.sigma * travelled));
}

std::vector<std::size_t> loop_candidates(const KeyframePlace& query, std::span<const KeyframePlace> earlier,
                                         const CandidateGate& gate, std::mt19937_64& rng) {
  std::vector<std::size_t> within;
  for (std::size_t j = 0; j < earlier.size(); ++j) {
    const double travelled = query.travelled - earlier[j].travelled;
    if (travelled < gate.exclude_recent_distance) continue;
    const double radius = search_radius(gate, travelled);
    if ((earlier[j].position - query.position).squaredNorm() < radius * radius) within.push_back(j);
  }
  if (within.size() > gate.max_candidates) {
    // The first max_candidates places of a partial Fisher-Yates shuffle.
    for (std::size_t k = 0; k < gate.max_candidates; ++k) {
      const std::size_t remaining = within.size() - k;
      const std::size_t pick = k + static_cast<std::size_t>(rng() % remaining);
      std::swap(within[k], within[pick]);
    }
    within.resize(gate.max_candidates);
    std::sort(within.begin(), within.end());
  }
  return within;
}

}  // namespace saloam
