#pragma once
// Spherical projection of a LiDAR scan into a range image, the input of a
// projection-based segmentation network (RangeNet++: Milioto et al., IROS
// 2019; SalsaNext: Cortinhal et al., ISVC 2020), and the map back from
// pixels to points.
//
// Rows (ProjectionSpec::row_mode):
//   kRing       row = the point's ring (beam index, 0 = top beam); the image
//               has one row per beam of the scan (exact for a spinning
//               sensor, whatever its elevation angles).
//   kElevation  RangeNet++'s projection: row = (1 - (e - fov_down) /
//               (fov_up - fov_down)) * rows for elevation e, clamped to the
//               image; the spacing is uniform in elevation.
// Columns: col = 0.5 * (1 - atan2(y, x) / pi) * columns (RangeNet++'s
// convention): column 0 looks backwards (azimuth +-180 deg), the middle
// column forwards, and columns increase clockwise seen from above.
// Each pixel shows its closest point (RangeNet++ writes far to near).
//
// Channels are stored channel-major (C x rows x columns, float), each value
// normalised as (v - mean) / std: range [m], x, y, z [m] (sensor frame, x
// forward, z up), remission [0, 1], mask (1 where a point is shown). Pixels
// without a point are 0 in every channel.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

enum class RowMode { kRing, kElevation };

enum class ImageChannel : std::uint8_t { kRange, kX, kY, kZ, kRemission, kMask };

/// "range", "x", "y", "z", "remission", "mask".
std::string_view channel_name(ImageChannel channel);

/// range, x, y, z, remission, mask: saloam's own networks' channels.
std::vector<ImageChannel> all_channels();

struct ProjectionSpec {
  RowMode row_mode = RowMode::kRing;
  int rows = 64;                 ///< kElevation: image rows (kRing: one per beam of the scan)
  double fov_up_deg = 3.0;       ///< kElevation: elevation of the top edge of row 0 [deg]
  double fov_down_deg = -25.0;   ///< kElevation: elevation of the bottom edge of the last row [deg]
  int columns = 2048;
  std::vector<ImageChannel> channels = all_channels();
  std::vector<float> means{0, 0, 0, 0, 0, 0};  ///< per channel
  std::vector<float> stds{1, 1, 1, 1, 1, 1};   ///< per channel, > 0
};

/// A projected scan. Pixel p = row * cols + col.
struct RangeImage {
  int rows = 0;
  int cols = 0;
  int channels = 0;
  std::vector<float> data;               ///< channels x rows x cols, normalised
  std::vector<float> range;              ///< per pixel: range of the shown point [m], -1 when none
  std::vector<std::int32_t> shown;       ///< per pixel: index of the shown point, -1 when none
  std::vector<std::int32_t> point_pixel; ///< per point: its pixel, -1 when it has none

  [[nodiscard]] std::size_t pixels() const { return range.size(); }
};

/// Projects `cloud`. `rings` (kRing only) holds each point's ring, -1 for a
/// point without one, and `beams` the number of rings (the image's rows).
/// Points that are not finite or at range 0 get no pixel.
RangeImage project_scan(const LabelledCloud& cloud, std::span<const std::int16_t> rings, int beams,
                        const ProjectionSpec& spec);

/// Column of a point at (x, y) in an image `columns` wide (see the header).
int projection_column(float x, float y, int columns);

}  // namespace saloam
