#pragma once
// A saved map as a localisation run uses it: the keyframes' poses and place
// descriptors in memory, their feature clouds read on demand and kept in a
// bounded cache (least recently used leave first), so memory follows the
// part of the map in use, not the whole map. Keyframes near a position are
// found through a 2D grid of their positions. It is a KeyframeSet: the
// place search (slam/place_search.hpp) searches it as it searches the live
// SLAM's keyframes.

#include <cstddef>
#include <functional>
#include <list>
#include <memory>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/types.hpp"
#include "saloam/maps/map_format.hpp"
#include "saloam/slam/place_search.hpp"

namespace saloam {

class PriorMap : public KeyframeSet {
 public:
  /// `load_features(k)` gives keyframe k's features (read_map_features for a
  /// map on disk); at most `cached` of them are held at once.
  PriorMap(SavedMap map, std::function<StoredFeatures(std::size_t)> load_features, std::size_t cached);
  /// A map on disk: read_map(folder), features read from it when needed.
  static PriorMap open(const std::filesystem::path& folder, std::size_t cached);
  /// A map on disk already read (`saved` = read_map(folder)), features read
  /// from `folder` when needed.
  static PriorMap open(const std::filesystem::path& folder, SavedMap saved, std::size_t cached);

  [[nodiscard]] const SavedMap& saved() const { return map_; }
  [[nodiscard]] std::size_t size() const override { return map_.keyframes.size(); }
  [[nodiscard]] Pose pose(std::size_t k) const override { return map_.keyframes[k].pose; }
  [[nodiscard]] std::uint32_t session(std::size_t k) const override { return map_.keyframes[k].session; }
  /// True unless keyframe k's session was not linked to the first (its poses in a frame of their own).
  [[nodiscard]] bool in_frame(std::size_t k) const override;
  [[nodiscard]] const PlaceDescriptor& place(std::size_t k) const override { return map_.places[k]; }
  /// From its session's up (MapSession::up) and its odometry pose.
  [[nodiscard]] Eigen::Matrix3d level(std::size_t k) const override { return levels_[k]; }
  /// Keyframe k's features (read when not cached).
  [[nodiscard]] std::shared_ptr<const StoredFeatures> features(std::size_t k) const;
  [[nodiscard]] ScanFeatures scan_features(std::size_t k) const override { return features(k)->expand(); }

  /// Keyframes whose position lies within `radius` of `position` (x-y and
  /// z), ascending.
  [[nodiscard]] std::vector<std::size_t> near(const Eigen::Vector3d& position, double radius) const override;

  [[nodiscard]] std::size_t loads() const { return loads_; }   ///< feature files read so far
  [[nodiscard]] std::size_t cached() const { return lru_.size(); }
  [[nodiscard]] std::size_t cached_bytes() const;

 private:
  SavedMap map_;
  std::vector<Eigen::Matrix3d> levels_;
  std::function<StoredFeatures(std::size_t)> load_;
  std::size_t capacity_;
  double cell_ = 20.0;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> grid_;
  mutable std::list<std::pair<std::size_t, std::shared_ptr<const StoredFeatures>>> lru_;
  mutable std::unordered_map<std::size_t, decltype(lru_)::iterator> index_;
  mutable std::size_t loads_ = 0;
};

}  // namespace saloam
