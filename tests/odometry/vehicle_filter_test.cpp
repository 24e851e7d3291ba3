// Driving vehicles stay out of the local map: a vehicle feature enters only
// when the previous frame saw a vehicle near it.

#include <gtest/gtest.h>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/odometry/vehicle_filter.hpp"

namespace saloam {
namespace {

const ClassIndex kCarIndex = to_learning_class(cls::kCar);
const ClassIndex kTruckIndex = to_learning_class(cls::kTruck);
const ClassIndex kBuildingIndex = to_learning_class(cls::kBuilding);

/// The back of a car 2 m wide and 1.2 m high at x = `back`, sampled every
/// `step` metres (offset by `phase`, as another scan samples it), as planar
/// features of class `c`; and a wall beside it.
ScanFeatures car_back_and_wall(double back, double step, double phase, ClassIndex c) {
  ScanFeatures f;
  for (double y = -1.0 + phase; y <= 1.0; y += step)
    for (double z = 0.2 + phase; z <= 1.4; z += step) f.planars.push_back({back, y, z}, c, 0.0f);
  for (double x = 0.0; x <= 20.0; x += 0.4) f.planars.push_back({x, 5.0, 1.0}, kBuildingIndex, 0.0f);
  f.edges.push_back({back, 1.0, 1.4}, c, 0.0f);
  return f;
}

std::size_t vehicles_in(const ScanFeatures& f) {
  std::size_t n = 0;
  for (const auto c : f.planars.classes) n += is_vehicle(c);
  for (const auto c : f.edges.classes) n += is_vehicle(c);
  return n;
}

TEST(VehicleFilter, VehiclesAreCarsTrucksAndTwoWheelers) {
  for (const auto raw : {cls::kCar, cls::kBicycle, cls::kMotorcycle, cls::kTruck, cls::kOtherVehicle})
    EXPECT_TRUE(is_vehicle(to_learning_class(raw))) << raw;
  for (const auto raw : {cls::kRoad, cls::kBuilding, cls::kPole, cls::kVegetation, cls::kPerson})
    EXPECT_FALSE(is_vehicle(to_learning_class(raw))) << raw;
  EXPECT_FALSE(is_vehicle(0)) << "the label-agnostic class";
}

TEST(VehicleFilter, AParkedCarEntersOneFrameLate) {
  VehicleFilter filter(0.5);
  ScanFeatures first = car_back_and_wall(10.0, 0.4, 0.0, kCarIndex);
  const std::size_t others = first.planars.size() + first.edges.size() - vehicles_in(first);
  filter.keep_confirmed(first);
  EXPECT_EQ(vehicles_in(first), 0U) << "nothing confirms a vehicle seen for the first time";
  EXPECT_EQ(first.planars.size() + first.edges.size(), others) << "other classes always enter";
  // The next scan samples the same car elsewhere on its surface, and calls
  // part of it a truck.
  ScanFeatures second = car_back_and_wall(10.0, 0.4, 0.17, kCarIndex);
  for (std::size_t i = 0; i < second.planars.size(); i += 2)
    if (is_vehicle(second.planars.classes[i])) second.planars.classes[i] = kTruckIndex;
  const std::size_t seen = vehicles_in(second);
  filter.keep_confirmed(second);
  EXPECT_EQ(vehicles_in(second), seen);
}

TEST(VehicleFilter, ACarDrivingAheadStaysOut) {
  VehicleFilter filter(0.5);
  // 10 m/s at 10 Hz: the back moves 1 m a frame.
  for (int frame = 0; frame < 5; ++frame) {
    ScanFeatures f = car_back_and_wall(10.0 + frame, 0.4, 0.0, kCarIndex);
    const std::size_t all = f.planars.size() + f.edges.size();
    const std::size_t vehicles = vehicles_in(f);
    ASSERT_GT(vehicles, 10U);
    filter.keep_confirmed(f);
    EXPECT_EQ(vehicles_in(f), 0U) << "frame " << frame;
    EXPECT_EQ(f.planars.size() + f.edges.size(), all - vehicles) << "frame " << frame;
  }
}

TEST(VehicleFilter, DistanceZeroKeepsEverything) {
  VehicleFilter filter(0.0);
  for (int frame = 0; frame < 3; ++frame) {
    ScanFeatures f = car_back_and_wall(10.0 + frame, 0.4, 0.0, kCarIndex);
    const std::size_t vehicles = vehicles_in(f);
    filter.keep_confirmed(f);
    EXPECT_EQ(vehicles_in(f), vehicles);
  }
}

}  // namespace
}  // namespace saloam
