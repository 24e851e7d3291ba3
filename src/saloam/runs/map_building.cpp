#include "saloam/runs/map_building.hpp"

#include <algorithm>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/progress.hpp"

namespace saloam {

LabelledCloud build_semantic_map(const SequenceReader& reader, const std::vector<Pose>& lidar_poses,
                                 std::size_t first_frame, const SemanticMapOptions& options, std::size_t frame_step,
                                 bool show_progress) {
  frame_step = std::max<std::size_t>(frame_step, 1);
  SemanticMap map(options);
  const std::size_t count = std::min(lidar_poses.size(), reader.size() - std::min(first_frame, reader.size()));
  ProgressBar progress((count + frame_step - 1) / frame_step, "map", show_progress);
  for (std::size_t k = 0; k < count && !stop_requested(); k += frame_step) {
    map.insert(reader.load_scan(first_frame + k), lidar_poses[k]);
    progress.advance();
  }
  progress.finish();
  return map.to_cloud();
}

}  // namespace saloam
