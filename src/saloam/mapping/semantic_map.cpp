#include "saloam/mapping/semantic_map.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "saloam/core/semantic_classes.hpp"

namespace saloam {

SemanticMapOptions SemanticMapOptions::from_config(const SlamConfig& config) {
  SemanticMapOptions options;
  options.voxel_size = config.map_voxel_size;
  return options;
}

SemanticMap::SemanticMap(SemanticMapOptions options) : options_(options) {}

void SemanticMap::insert(const LabelledCloud& scan, const Pose& world_from_sensor) {
  has_labels_ = has_labels_ || scan.has_labels;
  const Eigen::Affine3f T = world_from_sensor.cast<float>();
  const float inv_voxel = static_cast<float>(1.0 / options_.voxel_size);
  const float max_range_sq = static_cast<float>(options_.max_range * options_.max_range);
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const std::uint16_t label = scan.label[i];
    if (options_.skip_dynamic && is_dynamic(label)) continue;
    if (options_.skip_unlabeled && label == cls::kUnlabeled) continue;
    if (scan.points[i].squaredNorm() > max_range_sq) continue;
    const Eigen::Vector3f p = T * scan.points[i];
    const Eigen::Vector3i key((p * inv_voxel).array().floor().cast<int>());
    const auto [it, inserted] = index_.try_emplace(key, static_cast<std::uint32_t>(voxels_.size()));
    if (inserted) {
      keys_.push_back(key);
      voxels_.emplace_back();
    }
    Voxel& v = voxels_[it->second];
    v.sum += p;
    v.remission_sum += scan.remission[i];
    ++v.count;
    // Vote: an existing slot for this class, else an empty one, else replace
    // the weakest (a voxel rarely sees more than four classes).
    int slot = -1, weakest = 0;
    for (int s = 0; s < 4; ++s) {
      if (v.votes[s] > 0 && v.labels[s] == label) {
        slot = s;
        break;
      }
      if (v.votes[s] < v.votes[weakest]) weakest = s;
    }
    if (slot < 0) {
      slot = weakest;
      if (v.votes[slot] > 0) v.votes[slot] = 0;
      v.labels[slot] = label;
      v.instances[slot] = scan.instance[i];
    }
    ++v.votes[slot];
  }
}

LabelledCloud SemanticMap::to_cloud() const {
  // Sorted by voxel key so that the output does not depend on the order of insertion.
  std::vector<std::uint32_t> order(voxels_.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return std::lexicographical_compare(keys_[a].data(), keys_[a].data() + 3, keys_[b].data(), keys_[b].data() + 3);
  });
  LabelledCloud cloud;
  cloud.has_labels = has_labels_;
  cloud.reserve(order.size());
  for (const std::uint32_t i : order) {
    const Voxel& v = voxels_[i];
    const int best = static_cast<int>(std::max_element(v.votes, v.votes + 4) - v.votes);
    const float n = static_cast<float>(v.count);
    cloud.push_back(v.sum / n, v.remission_sum / n, v.labels[best], v.instances[best]);
  }
  return cloud;
}

}  // namespace saloam
