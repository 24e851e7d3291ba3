#pragma once
// Bird's-eye pictures of labelled points in the world frame (a semantic map,
// or scans accumulated with their poses): every pixel takes the class colour
// of the highest point above it (what a person sees from above), brighter
// where that point stands higher over the lowest one in the pixel (facades,
// trees and cars stand out from the ground, on flat and hilly routes alike),
// with the trajectory drawn on top (white, start green, end red).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/types.hpp"

namespace saloam {

/// A straight segment between two world points (x east, y north, z up).
using WorldSegment = std::pair<Eigen::Vector3d, Eigen::Vector3d>;

struct TopDownOptions {
  double metres_per_pixel = 0.0;  ///< 0 = fit the extent into `max_pixels`; widened if it would exceed them
  int max_pixels = 2000;          ///< longest image side
  bool draw_trajectory = true;
};

struct TopDownStats {
  std::size_t points_drawn = 0;  ///< points that fell inside the picture
  int width = 0, height = 0;
  double metres_per_pixel = 0;
};

/// A top-down picture filled point by point, so that a long sequence can be
/// drawn scan by scan without holding all its points.
class TopDownCanvas {
 public:
  /// Picture of the world rectangle [lo, hi] (x east, y north; north up).
  TopDownCanvas(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, const TopDownOptions& options = {});

  /// A point in the world frame (z up) with its raw SemanticKITTI class
  /// (`labelled` false: coloured by height instead).
  void add(const Eigen::Vector3d& point, std::uint16_t label, bool labelled = true);
  /// Every point of `cloud` (already in the world frame).
  void add(const LabelledCloud& cloud);

  /// Writes the PNG with the trajectory positions drawn over the points and
  /// `links` (e.g. accepted loop closures, world frame) in orange over both.
  TopDownStats save(const std::filesystem::path& png, const std::vector<Pose>& trajectory,
                    const std::vector<WorldSegment>& links = {}) const;

  [[nodiscard]] const TopDownStats& stats() const { return stats_; }
  /// Class shown at world position (x, y): that of the highest point in its
  /// pixel; 0 where nothing was drawn or outside the picture.
  [[nodiscard]] std::uint16_t shown_label(double x, double y) const;

 private:
  [[nodiscard]] Eigen::Vector2i pixel(double x, double y) const;

  TopDownOptions options_;
  Eigen::Vector2d lo_, hi_;
  TopDownStats stats_;
  std::vector<float> top_, bottom_;  ///< highest and lowest z per pixel
  std::vector<std::uint16_t> label_;
  bool any_labelled_ = false;
  float zmin_, zmax_;
};

/// Renders `map` (world frame, z up), the trajectory positions and `links`
/// to a PNG, framing map and trajectory with a 5 m margin.
TopDownStats render_top_down(const std::filesystem::path& png, const LabelledCloud& map,
                             const std::vector<Pose>& trajectory, const TopDownOptions& options = {},
                             const std::vector<WorldSegment>& links = {});

}  // namespace saloam
