#pragma once
// A SLAM run's state as a saved map (map_format.hpp): its keyframes with
// their optimised poses, features and place descriptors, the pose graph's
// edges, and the configuration.

#include <filesystem>

#include "saloam/core/config.hpp"
#include "saloam/maps/map_format.hpp"
#include "saloam/slam/slam_system.hpp"

namespace saloam {

/// The map of `slam` (features not copied: write_slam_map reads them from
/// the system). `manifest` supplies sensor, source, first frame and Tr.
SavedMap saved_map_of(const SlamSystem& slam, const SaloamConfig& config, const MapManifest& manifest);

/// Writes the map of `slam` into `folder` (write_map).
void write_slam_map(const std::filesystem::path& folder, const SlamSystem& slam, const SaloamConfig& config,
                    const MapManifest& manifest);

}  // namespace saloam
