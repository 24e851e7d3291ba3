#pragma once
// Driving vehicles out of the local map.
//
// A scan's labels say "car", not whether the car is parked or driving: a
// single-scan segmentation network cannot tell (ground-truth labels can, and
// mark driving ones moving-car, which the odometry drops). A driving car
// that enters the local map pulls the next scans along with it: its back,
// seen by a sensor that follows it at its speed, stays where the map has it,
// and the registration under-measures the sensor's own motion. So a vehicle
// feature (car, bicycle, motorcycle, truck, other-vehicle) enters the map
// only when the previous frame saw a vehicle feature within
// `confirmation_distance` of it in the world frame. A parked vehicle enters
// one frame late; the faces of a driving one across its motion (displaced
// between frames by its own motion, 1 m at 36 km/h and 10 Hz) stay out,
// while faces along its motion, which constrain nothing along it, may enter.
// The registration itself is unchanged: a driving vehicle's points then find
// no vehicle in the map to match.

#include "saloam/odometry/features.hpp"
#include "saloam/odometry/local_map.hpp"

namespace saloam {

/// A vehicle class (car, bicycle, motorcycle, truck, other-vehicle) as a class index.
bool is_vehicle(ClassIndex c);

class VehicleFilter {
 public:
  /// [m] `confirmation_distance` 0: every vehicle feature enters the map at once.
  explicit VehicleFilter(double confirmation_distance);

  /// Drops from `world` (features of this frame in the world frame) the
  /// vehicle features that no vehicle feature of the previous call
  /// confirms, and remembers this frame's vehicle features for the next.
  void keep_confirmed(ScanFeatures& world);

 private:
  double distance_;
  NeighbourGrid previous_;
};

}  // namespace saloam
