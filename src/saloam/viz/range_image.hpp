#pragma once
// Range image of one scan for judging it by eye: rows are the beams (by
// elevation, top first), columns the azimuth in the LiDAR frame (front in the
// middle, the car's left on the picture's left); class colours on top, range
// (viridis, near is bright) below.

#include <filesystem>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

/// Writes the range image of `cloud` to `png`. A point goes to the row of the
/// beam whose elevation [deg] in `elevation_deg` (top first) is nearest its
/// own, atan2(z, hypot(x, y)), and is left out when none is within 1 deg; of
/// the points falling into one pixel the nearest is drawn.
void render_range_image(const LabelledCloud& cloud, const std::filesystem::path& png,
                        const std::vector<double>& elevation_deg, int columns = 1040);

}  // namespace saloam
