#pragma once
// Bird's-eye pictures of a labelled map: every pixel takes the class colour
// of the highest map point above it (what a person sees from above), shaded
// by height, with the trajectory drawn on top.

#include <filesystem>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

struct TopDownOptions {
  double metres_per_pixel = 0.0;  ///< 0 = fit the map into `max_pixels`
  int max_pixels = 2000;          ///< longest image side when fitting
  bool draw_trajectory = true;
};

/// Renders `map` (world frame, z up) and the trajectory positions to a PNG.
void render_top_down(const std::filesystem::path& png, const LabelledCloud& map,
                     const std::vector<Pose>& trajectory, const TopDownOptions& options = {});

}  // namespace saloam
