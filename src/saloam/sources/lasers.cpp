#include "saloam/sources/lasers.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>

#include <Eigen/Eigenvalues>

namespace saloam {
namespace {

constexpr double kNearHorizontal = 2.0;  ///< [m] points nearer than this blur the elevation (sensor offsets)

double elevation_deg(const Eigen::Vector3f& p) {
  return std::atan2(static_cast<double>(p.z()), std::hypot(static_cast<double>(p.x()), static_cast<double>(p.y()))) *
         180.0 / std::numbers::pi;
}

/// Elevation [deg] above the plane normal to a unit `axis`.
double elevation_deg(const Eigen::Vector3f& p, const Eigen::Vector3d& axis) {
  const Eigen::Vector3d d = p.cast<double>().normalized();
  return std::asin(std::clamp(d.dot(axis), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

/// A spin axis closer than this to the cloud's z is the cloud's z [deg].
constexpr double kAxisTolerance = 1.0;

/// The axis the lasers spin about: each laser's returns lie on a cone about
/// it (d . axis = sin of the laser's elevation), so it is the direction in
/// which the lasers' unit directions vary least about their means (the
/// smallest eigenvector of the summed covariances), on the side of the
/// cloud's z. The cloud's z when that is within kAxisTolerance, or when
/// too few lasers tell.
Eigen::Vector3d spin_axis(const LabelledCloud& cloud, const std::vector<std::vector<std::uint32_t>>& lasers) {
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  std::size_t used = 0;
  for (const auto& laser : lasers) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    std::size_t n = 0;
    for (const std::uint32_t i : laser) {
      const Eigen::Vector3d p = cloud.points[i].cast<double>();
      if (p.norm() <= kNearHorizontal || !p.allFinite()) continue;
      const Eigen::Vector3d d = p.normalized();
      sum += d;
      outer.noalias() += d * d.transpose();
      ++n;
    }
    if (n < 10) continue;
    const Eigen::Vector3d mean = sum / static_cast<double>(n);
    scatter += outer - static_cast<double>(n) * mean * mean.transpose();
    ++used;
  }
  if (used < 2) return Eigen::Vector3d::UnitZ();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  Eigen::Vector3d axis = eig.eigenvectors().col(0).normalized();
  if (axis.z() < 0) axis = -axis;
  if (!axis.allFinite() || std::acos(std::clamp(axis.z(), -1.0, 1.0)) * 180.0 / std::numbers::pi < kAxisTolerance) {
    return Eigen::Vector3d::UnitZ();
  }
  return axis;
}

double azimuth(const Eigen::Vector3f& p) { return std::atan2(static_cast<double>(p.y()), static_cast<double>(p.x())); }

/// Median elevation (about `axis`) of each group's points beyond kNearHorizontal (all of them when none is).
std::vector<double> median_elevations(const LabelledCloud& cloud, const std::vector<std::vector<std::uint32_t>>& groups,
                                      const Eigen::Vector3d& axis) {
  std::vector<double> out;
  for (const auto& group : groups) {
    std::vector<double> far, all;
    for (const std::uint32_t i : group) {
      const auto& p = cloud.points[i];
      const double e = axis.z() == 1.0 ? elevation_deg(p) : elevation_deg(p, axis);
      all.push_back(e);
      if (std::hypot(p.x(), p.y()) > kNearHorizontal) far.push_back(e);
    }
    auto& use = far.empty() ? all : far;
    if (use.empty()) continue;
    std::nth_element(use.begin(), use.begin() + static_cast<std::ptrdiff_t>(use.size() / 2), use.end());
    out.push_back(use[use.size() / 2]);
  }
  std::sort(out.begin(), out.end(), std::greater<>());
  return out;
}

/// The laser of every point when the cloud is stored laser after laser (see
/// the header), else nullopt.
std::optional<std::vector<std::uint32_t>> laser_by_storage(const LabelledCloud& cloud) {
  if (cloud.size() < 200) return std::nullopt;
  std::size_t forward = 0, backward = 0, wraps = 0;
  double previous = azimuth(cloud.points[0]);
  for (std::size_t i = 1; i < cloud.size(); ++i) {
    const double a = azimuth(cloud.points[i]);
    const double step = a - previous;
    previous = a;
    if (std::abs(step) > std::numbers::pi) ++wraps;
    else if (step > 0.0) ++forward;
    else if (step < 0.0) ++backward;
  }
  const std::size_t steps = forward + backward;
  if (steps == 0 || 10 * std::max(forward, backward) <= 9 * steps || wraps == 0 || cloud.size() / wraps < 100) {
    return std::nullopt;
  }
  const double sense = forward > backward ? 1.0 : -1.0;
  std::vector<std::uint32_t> laser(cloud.size());
  double turned = 0.0;  // unwrapped azimuth travelled in the turning sense since the first point
  previous = azimuth(cloud.points[0]);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double a = azimuth(cloud.points[i]);
    double step = sense * (a - previous);
    if (step < -std::numbers::pi) step += 2.0 * std::numbers::pi;
    if (step > std::numbers::pi) step -= 2.0 * std::numbers::pi;
    turned += step;
    previous = a;
    laser[i] = static_cast<std::uint32_t>(std::max(0.0, std::floor((turned + 1e-6) / (2.0 * std::numbers::pi))));
  }
  return laser;
}

std::vector<double> elevation_clusters(const LabelledCloud& cloud) {
  std::vector<double> elevation;
  elevation.reserve(cloud.size());
  for (const auto& p : cloud.points) {
    if (std::hypot(p.x(), p.y()) > kNearHorizontal) elevation.push_back(elevation_deg(p));
  }
  std::sort(elevation.begin(), elevation.end(), std::greater<>());
  const std::size_t min_points = std::max<std::size_t>(1, elevation.size() / 1000);
  constexpr double kGap = 0.15;  // [deg]
  std::vector<double> centres;
  std::size_t first = 0;
  for (std::size_t i = 1; i <= elevation.size(); ++i) {
    if (i < elevation.size() && elevation[i - 1] - elevation[i] <= kGap) continue;
    if (i - first >= min_points) centres.push_back(elevation[first + (i - first) / 2]);
    first = i;
  }
  return centres;
}

}  // namespace

FoundLasers find_lasers(const LabelledCloud& cloud) {
  FoundLasers found;
  std::optional<std::vector<std::uint32_t>> laser;
  if (cloud.has_rings()) {
    laser.emplace(cloud.ring.begin(), cloud.ring.end());
    found.method = BeamMethod::kRingField;
  } else if ((laser = laser_by_storage(cloud))) {
    found.method = BeamMethod::kAzimuthWraps;
  } else {
    found.method = BeamMethod::kElevation;
    found.elevation_deg = elevation_clusters(cloud);
    return found;
  }
  std::map<std::uint32_t, std::vector<std::uint32_t>> groups;
  for (std::size_t i = 0; i < cloud.size(); ++i) groups[(*laser)[i]].push_back(static_cast<std::uint32_t>(i));
  // In storage order a last laser that runs on past the first point's
  // azimuth leaves a few points beyond the last full turn: not a laser.
  const std::size_t min_points = found.method == BeamMethod::kAzimuthWraps ? cloud.size() / groups.size() / 10 : 1;
  std::vector<std::vector<std::uint32_t>> members;
  for (auto& [l, m] : groups) {
    if (m.size() >= min_points) members.push_back(std::move(m));
  }
  found.spin_axis = spin_axis(cloud, members);
  found.elevation_deg = median_elevations(cloud, members, found.spin_axis);
  return found;
}

const char* beam_method_text(BeamMethod method) {
  switch (method) {
    case BeamMethod::kRingField: return "ring field";
    case BeamMethod::kAzimuthWraps: return "points stored laser by laser";
    case BeamMethod::kElevation: break;
  }
  return "elevation angles; no ring field";
}

}  // namespace saloam
