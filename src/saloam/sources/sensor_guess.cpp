#include "saloam/sources/sensor_guess.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace saloam {
namespace {

constexpr double kUncovered = 3.0, kUnused = 0.3, kResidual = 10.0, kSlack = 1.0;  // see the header

/// Mean distance [deg] of `found` to the nearest of `lasers` (top first).
double mean_residual(const std::vector<double>& found, const std::vector<double>& lasers) {
  double sum = 0.0;
  for (const double e : found) {
    const auto below = std::lower_bound(lasers.begin(), lasers.end(), e, std::greater<>());
    double best = 180.0;
    if (below != lasers.end()) best = std::min(best, e - *below);
    if (below != lasers.begin()) best = std::min(best, *(below - 1) - e);
    sum += best;
  }
  return found.empty() ? 0.0 : sum / static_cast<double>(found.size());
}

}  // namespace

std::string SensorGuess::found() const {
  if (lasers.elevation_deg.empty()) return fmt::format("no laser found ({})", beam_method_text(lasers.method));
  std::string text = fmt::format("{} lasers ({}) from {:+.1f} to {:+.1f} deg", lasers.count(),
                                 beam_method_text(lasers.method), lasers.elevation_deg.front(), lasers.elevation_deg.back());
  const Eigen::Vector3d& axis = lasers.spin_axis;
  if (axis.z() < 1.0) {
    text += fmt::format(" about their spin axis ({:.3f}, {:.3f}, {:.3f}), {:.1f} deg from the cloud's z", axis.x(), axis.y(),
                        axis.z(), std::acos(std::clamp(axis.z(), -1.0, 1.0)) * 180.0 / M_PI);
  }
  return text;
}

double sensor_score(const SensorProfile& profile, const FoundLasers& lasers) {
  if (lasers.elevation_deg.empty() || profile.elevation_deg.empty()) return 1e9;
  const double top = lasers.elevation_deg.front(), bottom = lasers.elevation_deg.back();
  const double p_top = profile.elevation_deg.front(), p_bottom = profile.elevation_deg.back();
  const double uncovered = std::max(0.0, top - (p_top + kSlack)) + std::max(0.0, (p_bottom - kSlack) - bottom);
  const double unused = std::max(0.0, p_top - top) + std::max(0.0, bottom - p_bottom);
  double score = kUncovered * uncovered + kUnused * unused;
  const auto found = static_cast<double>(lasers.count()), beams = static_cast<double>(profile.beams());
  if (lasers.exact()) {
    score += kResidual * mean_residual(lasers.elevation_deg, profile.elevation_deg);
    if (lasers.count() != static_cast<std::size_t>(profile.beams())) score += 4.0;
  } else {
    score += 2.0 * std::abs(std::log2(found / beams));
  }
  return score;
}

std::optional<SensorProfile> laser_subset(const SensorProfile& profile, const FoundLasers& lasers) {
  const auto& lasers_of = profile.elevation_deg;
  if (!lasers.exact() || lasers.count() == 0 || 2 * lasers.count() > lasers_of.size()) return std::nullopt;
  std::vector<double> kept;
  for (const double e : lasers.elevation_deg) {
    const auto nearest = std::min_element(lasers_of.begin(), lasers_of.end(),
                                          [e](double a, double b) { return std::abs(a - e) < std::abs(b - e); });
    if (!kept.empty() && !(*nearest < kept.back())) return std::nullopt;  // two lasers on one, or out of order
    kept.push_back(*nearest);
  }
  SensorProfile subset = profile;
  subset.elevation_deg = std::move(kept);
  return subset;
}

SensorGuess guess_sensor(const LabelledCloud& scan, const std::vector<SensorProfile>& profiles) {
  if (profiles.empty()) throw ConfigError("no sensor profile to choose from");
  SensorGuess guess;
  guess.lasers = find_lasers(scan);
  guess.score = sensor_score(profiles.front(), guess.lasers);
  for (std::size_t i = 1; i < profiles.size(); ++i) {
    const double s = sensor_score(profiles[i], guess.lasers);
    if (s < guess.score) {
      guess.score = s;
      guess.profile = i;
    }
  }
  return guess;
}

}  // namespace saloam
