#include "saloam/maps/slam_map.hpp"

namespace saloam {

SavedMap saved_map_of(const SlamSystem& slam, const SaloamConfig& config, const MapManifest& manifest) {
  SavedMap map;
  map.manifest = manifest;
  map.config = config;
  map.manifest.detector = config.loop.detector;
  const auto& keyframes = slam.keyframes();
  map.keyframes.reserve(keyframes.size());
  map.places.reserve(keyframes.size());
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    MapKeyframe kf;
    kf.frame = keyframes[k].frame;
    kf.timestamp = keyframes[k].timestamp;
    kf.travelled = keyframes[k].travelled;
    kf.pose = slam.keyframe_pose(k);
    kf.odometry_pose = keyframes[k].odometry_pose;
    map.keyframes.push_back(kf);
    map.places.push_back(keyframes[k].place);
  }
  map.edges = slam.graph().edges();
  // One session, described level with the run's up (in its odometry frame).
  MapSession session = map_sessions(map).front();
  session.up = slam.odometry().up();
  map.manifest.sessions = {session};
  return map;
}

void write_slam_map(const std::filesystem::path& folder, const SlamSystem& slam, const SaloamConfig& config,
                    const MapManifest& manifest) {
  const SavedMap map = saved_map_of(slam, config, manifest);
  write_map(folder, map, [&](std::size_t k) -> const StoredFeatures& { return slam.keyframes()[k].features; });
}

}  // namespace saloam
