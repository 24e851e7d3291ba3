#include "saloam/maps/prior_map.hpp"

#include <algorithm>
#include <cmath>

#include "saloam/odometry/gravity.hpp"

namespace saloam {

namespace {
std::int64_t cell_key(std::int64_t x, std::int64_t y) { return (x << 32) ^ (y & 0xffffffffLL); }
}  // namespace

PriorMap::PriorMap(SavedMap map, std::function<StoredFeatures(std::size_t)> load_features, std::size_t cached)
    : map_(std::move(map)), load_(std::move(load_features)), capacity_(std::max<std::size_t>(1, cached)) {
  const std::vector<MapSession> sessions = map_sessions(map_);
  levels_.reserve(map_.keyframes.size());
  for (const MapKeyframe& kf : map_.keyframes) {
    const Eigen::Vector3d up = kf.session < sessions.size() ? sessions[kf.session].up : Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d sensor_up = kf.odometry_pose.linear().transpose() * up;
    levels_.push_back(points_up(sensor_up) ? Eigen::Matrix3d::Identity() : level_rotation(sensor_up));
  }
  for (std::size_t k = 0; k < map_.keyframes.size(); ++k) {
    const Eigen::Vector3d& p = map_.keyframes[k].pose.translation();
    grid_[cell_key(static_cast<std::int64_t>(std::floor(p.x() / cell_)), static_cast<std::int64_t>(std::floor(p.y() / cell_)))]
        .push_back(k);
  }
}

PriorMap PriorMap::open(const std::filesystem::path& folder, std::size_t cached) {
  return open(folder, read_map(folder), cached);
}

PriorMap PriorMap::open(const std::filesystem::path& folder, SavedMap saved, std::size_t cached) {
  // What a features read checks against (folder, identity, digests), kept apart from the tables.
  auto digests = std::make_shared<SavedMap>();
  digests->folder = folder;
  digests->manifest = saved.manifest;
  digests->feature_digests = saved.feature_digests;
  return PriorMap(std::move(saved), [digests](std::size_t k) { return read_map_features(*digests, k); }, cached);
}

std::shared_ptr<const StoredFeatures> PriorMap::features(std::size_t k) const {
  if (const auto it = index_.find(k); it != index_.end()) {
    lru_.splice(lru_.begin(), lru_, it->second);
    return it->second->second;
  }
  auto features = std::make_shared<const StoredFeatures>(load_(k));
  ++loads_;
  lru_.emplace_front(k, features);
  index_[k] = lru_.begin();
  while (lru_.size() > capacity_) {
    index_.erase(lru_.back().first);
    lru_.pop_back();
  }
  return features;
}

std::vector<std::size_t> PriorMap::near(const Eigen::Vector3d& position, double radius) const {
  std::vector<std::size_t> found;
  if (!(radius > 0) || !position.allFinite()) return found;
  const auto x0 = static_cast<std::int64_t>(std::floor((position.x() - radius) / cell_));
  const auto x1 = static_cast<std::int64_t>(std::floor((position.x() + radius) / cell_));
  const auto y0 = static_cast<std::int64_t>(std::floor((position.y() - radius) / cell_));
  const auto y1 = static_cast<std::int64_t>(std::floor((position.y() + radius) / cell_));
  if (x1 - x0 > 10000 || y1 - y0 > 10000) return found;
  for (std::int64_t y = y0; y <= y1; ++y) {
    for (std::int64_t x = x0; x <= x1; ++x) {
      const auto it = grid_.find(cell_key(x, y));
      if (it == grid_.end()) continue;
      for (const std::size_t k : it->second) {
        if ((map_.keyframes[k].pose.translation() - position).norm() <= radius) found.push_back(k);
      }
    }
  }
  std::sort(found.begin(), found.end());
  return found;
}

bool PriorMap::in_frame(std::size_t k) const {
  const std::uint32_t s = map_.keyframes[k].session;
  return s >= map_.manifest.sessions.size() || map_.manifest.sessions[s].linked;
}

std::size_t PriorMap::cached_bytes() const {
  std::size_t bytes = 0;
  for (const auto& [k, f] : lru_) bytes += f->bytes();
  return bytes;
}

}  // namespace saloam
