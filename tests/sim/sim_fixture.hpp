#pragma once
// Shared, lazily built simulator state for the sim tests (the urban-loop
// world takes ~0.1 s to build; built once per test binary).

#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/sim/lidar.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sim/trajectories.hpp"
#include "saloam/sim/world.hpp"

namespace saloam::testing {

inline const std::vector<Pose>& urban_loop() {
  static const std::vector<Pose> poses = preset_trajectory("urban-loop");
  return poses;
}

inline const World& urban_world() {
  static const World world = build_world(urban_loop(), 7);
  return world;
}

inline SweepSpec sweep_at(std::size_t frame, bool skew = true, std::uint64_t seed = 7) {
  SimulationOptions options;
  options.seed = seed;
  options.skew = skew;
  return sweep_for_frame(urban_loop(), frame, options);
}

inline LidarModel lidar_model(int beams, int azimuth_steps = 2083) {
  LidarModel lidar = LidarModel::hdl64e(beams);
  lidar.azimuth_steps = azimuth_steps;
  return lidar;
}

inline SimulatedScan scan_at(std::size_t frame, int beams, bool skew = true, std::uint64_t seed = 7,
                             int azimuth_steps = 2083) {
  return simulate_scan(urban_world(), lidar_model(beams, azimuth_steps), sweep_at(frame, skew, seed));
}

/// Points of a scan (made by scan_at with the same arguments) in the world frame.
inline std::vector<Eigen::Vector3d> to_world(const SimulatedScan& scan, std::size_t frame, int beams, bool skew = true,
                                             std::uint64_t seed = 7, int azimuth_steps = 2083) {
  return points_in_world(scan, lidar_model(beams, azimuth_steps), sweep_at(frame, skew, seed));
}

}  // namespace saloam::testing
