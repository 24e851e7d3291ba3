#include "saloam/odometry/vehicle_filter.hpp"

#include <algorithm>

#include "saloam/core/semantic_classes.hpp"

namespace saloam {

namespace {

/// Every vehicle point of `world` goes into one class of the grid: a car
/// called a truck in the next scan is the same vehicle.
constexpr ClassIndex kVehicles = 0;

void keep_confirmed_points(FeatureCloud& cloud, const NeighbourGrid& previous, double distance,
                           std::vector<Eigen::Vector3d>& vehicles) {
  FeatureCloud kept;
  kept.points.reserve(cloud.size());
  kept.classes.reserve(cloud.size());
  kept.sweep_time.reserve(cloud.size());
  Eigen::Vector3d neighbour;
  double squared_distance = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.points[i];
    if (is_vehicle(cloud.classes[i])) {
      vehicles.push_back(p);
      if (previous.nearest(p, kVehicles, 1, distance, &neighbour, &squared_distance) == 0) continue;
    }
    kept.push_back(p, cloud.classes[i], cloud.sweep_time[i]);
  }
  cloud = std::move(kept);
}

}  // namespace

bool is_vehicle(ClassIndex c) {
  static const auto vehicles = [] {
    std::array<bool, kNumClassIndices> v{};
    for (const auto raw : {cls::kCar, cls::kBicycle, cls::kMotorcycle, cls::kTruck, cls::kOtherVehicle})
      v[to_learning_class(raw)] = true;
    return v;
  }();
  return c < vehicles.size() && vehicles[c];
}

VehicleFilter::VehicleFilter(double confirmation_distance)
    : distance_(confirmation_distance), previous_(std::max(confirmation_distance, 0.1)) {}

void VehicleFilter::keep_confirmed(ScanFeatures& world) {
  if (distance_ <= 0) return;
  std::vector<Eigen::Vector3d> vehicles;
  keep_confirmed_points(world.edges, previous_, distance_, vehicles);
  keep_confirmed_points(world.planars, previous_, distance_, vehicles);
  previous_ = NeighbourGrid(std::max(distance_, 0.1));
  for (const auto& p : vehicles) previous_.insert(p, kVehicles);
}

}  // namespace saloam
