#include "saloam/runs/map_building.hpp"

#include <algorithm>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/progress.hpp"

namespace saloam {

LabelledCloud build_semantic_map(FrameSource& source, const std::vector<Pose>& lidar_poses, std::size_t first_frame,
                                 const SemanticMapOptions& options, std::size_t frame_step, bool show_progress) {
  frame_step = std::max<std::size_t>(frame_step, 1);
  SemanticMap map(options);
  const std::size_t count = std::min(lidar_poses.size(), source.size() - std::min(first_frame, source.size()));
  ProgressBar progress((count + frame_step - 1) / frame_step, "map", show_progress);
  for (std::size_t k = 0; k < count && !stop_requested(); k += frame_step) {
    map.insert(source.scan(first_frame + k), lidar_poses[k]);
    progress.advance();
  }
  progress.finish();
  return map.to_cloud();
}

MapScanStore::MapScanStore(SemanticMapOptions options, std::size_t frame_step)
    : options_(options), frame_step_(std::max<std::size_t>(frame_step, 1)) {}

void MapScanStore::offer(std::size_t k, const LabelledCloud& scan) {
  if (k % frame_step_ != 0) return;
  SemanticMap downsampled(options_);
  downsampled.insert(scan, Pose::Identity());
  frames_.push_back(k);
  scans_.push_back(downsampled.to_cloud());
}

LabelledCloud MapScanStore::build(const std::vector<Pose>& lidar_poses, bool show_progress) const {
  SemanticMap map(options_);
  ProgressBar progress(scans_.size(), "map", show_progress);
  for (std::size_t s = 0; s < scans_.size() && !stop_requested(); ++s) {
    if (frames_[s] >= lidar_poses.size()) break;
    map.insert(scans_[s], lidar_poses[frames_[s]]);
    progress.advance();
  }
  progress.finish();
  return map.to_cloud();
}

std::size_t MapScanStore::bytes() const {
  std::size_t total = 0;
  for (const auto& s : scans_) {
    total += s.size() * (sizeof(Eigen::Vector3f) + sizeof(float) + 2 * sizeof(std::uint16_t));
  }
  return total;
}

}  // namespace saloam
