#include "saloam/runs/map_building.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/progress.hpp"

namespace saloam {

LabelledCloud build_semantic_map(FrameSource& source, const std::vector<Pose>& lidar_poses,
                                 const SemanticMapOptions& options, std::size_t frame_step, bool show_progress) {
  frame_step = std::max<std::size_t>(frame_step, 1);
  SemanticMap map(options);
  const std::size_t count = std::min(lidar_poses.size(), source.size());
  ProgressBar progress((count + frame_step - 1) / frame_step, "map", show_progress);
  for (std::size_t k = 0; k < count && !stop_requested(); k += frame_step) {
    map.insert(source.scan(k), lidar_poses[k]);
    progress.advance();
  }
  progress.finish();
  return map.to_cloud();
}

MapScanStore::MapScanStore(SemanticMapOptions options, std::size_t frame_step)
    : options_(options), frame_step_(std::max<std::size_t>(frame_step, 1)) {
  if (!(options_.max_range <= 300.0)) {
    throw std::invalid_argument("MapScanStore keeps centimetre coordinates in 16 bits: map range at most 300 m");
  }
}

void MapScanStore::offer(std::size_t k, const LabelledCloud& scan) {
  if (k % frame_step_ != 0) return;
  SemanticMap downsampled(options_);
  downsampled.insert(scan, Pose::Identity());
  const LabelledCloud voxels = downsampled.to_cloud();
  std::vector<CompactPoint> compact(voxels.size());
  const auto centimetres = [](float metres) { return static_cast<std::int16_t>(std::lround(metres * 100.0f)); };
  for (std::size_t i = 0; i < voxels.size(); ++i) {
    const Eigen::Vector3f& p = voxels.points[i];
    compact[i] = {centimetres(p.x()), centimetres(p.y()), centimetres(p.z()), voxels.label[i],
                  static_cast<std::uint8_t>(std::lround(std::clamp(voxels.remission[i], 0.0f, 1.0f) * 255.0f))};
  }
  frames_.push_back(k);
  scans_.push_back(std::move(compact));
}

LabelledCloud MapScanStore::build(const std::vector<Pose>& lidar_poses, bool show_progress) const {
  SemanticMap map(options_);
  ProgressBar progress(scans_.size(), "map", show_progress);
  LabelledCloud scan;
  scan.has_labels = true;
  for (std::size_t s = 0; s < scans_.size() && !stop_requested(); ++s) {
    if (frames_[s] >= lidar_poses.size()) break;
    scan.clear();
    for (const CompactPoint& c : scans_[s]) {
      scan.push_back(Eigen::Vector3f(c.x, c.y, c.z) * 0.01f, c.remission / 255.0f, c.label, 0);
    }
    map.insert(scan, lidar_poses[frames_[s]]);
    progress.advance();
  }
  progress.finish();
  return map.to_cloud();
}

std::size_t MapScanStore::bytes() const {
  std::size_t total = 0;
  for (const auto& s : scans_) total += s.size() * sizeof(CompactPoint);
  return total;
}

}  // namespace saloam
