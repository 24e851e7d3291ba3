#include "saloam/segmentation/range_projection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace saloam {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Rows of the image and the row of each point (-1: none).
struct RowAssignment {
  int rows = 0;
  std::vector<std::int32_t> row;
};

RowAssignment rows_by_ring(const LabelledCloud& cloud, std::span<const std::int16_t> rings, int beams) {
  if (rings.size() != cloud.size()) throw std::invalid_argument("project_scan: one ring per point expected");
  RowAssignment out{beams, std::vector<std::int32_t>(cloud.size(), -1)};
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (rings[i] >= 0 && rings[i] < beams) out.row[i] = rings[i];
  return out;
}

RowAssignment rows_by_elevation(const LabelledCloud& cloud, const ProjectionSpec& spec) {
  RowAssignment out{spec.rows, std::vector<std::int32_t>(cloud.size(), -1)};
  const double up = spec.fov_up_deg * kPi / 180.0;
  const double fov = (spec.fov_up_deg - spec.fov_down_deg) * kPi / 180.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    const double r = p.norm();
    if (!(r > 0.0) || !std::isfinite(r)) continue;
    const double elevation = std::asin(std::clamp(static_cast<double>(p.z()) / r, -1.0, 1.0));
    const auto row = static_cast<int>(std::floor((up - elevation) / fov * spec.rows));
    out.row[i] = std::clamp(row, 0, spec.rows - 1);
  }
  return out;
}

/// image.data from the points the pixels show: every channel of a pixel is
/// written together, so that each point is read once.
void fill_channels(RangeImage& image, const LabelledCloud& cloud, const ProjectionSpec& spec) {
  const std::size_t pixels = image.pixels();
  const auto channels = static_cast<std::size_t>(image.channels);
  image.data.assign(channels * pixels, 0.0f);
  std::vector<float> inv_std(channels);
  for (std::size_t c = 0; c < channels; ++c) inv_std[c] = 1.0f / spec.stds[c];
  for (std::size_t px = 0; px < pixels; ++px) {
    const std::int32_t i = image.shown[px];
    if (i < 0) continue;
    const auto k = static_cast<std::size_t>(i);
    const Eigen::Vector3f& p = cloud.points[k];
    const std::array<float, 6> raw{image.range[px], p.x(), p.y(), p.z(), cloud.remission[k], 1.0f};  // ImageChannel order
    float* value = image.data.data() + px;
    for (std::size_t c = 0; c < channels; ++c, value += pixels)
      *value = (raw[static_cast<std::size_t>(spec.channels[c])] - spec.means[c]) * inv_std[c];
  }
}

}  // namespace

std::vector<ImageChannel> all_channels() {
  std::vector<ImageChannel> channels;
  for (int c = 0; c <= static_cast<int>(ImageChannel::kMask); ++c) channels.push_back(static_cast<ImageChannel>(c));
  return channels;
}

std::string_view channel_name(ImageChannel channel) {
  switch (channel) {
    case ImageChannel::kRange: return "range";
    case ImageChannel::kX: return "x";
    case ImageChannel::kY: return "y";
    case ImageChannel::kZ: return "z";
    case ImageChannel::kRemission: return "remission";
    case ImageChannel::kMask: return "mask";
  }
  return "?";
}

int projection_column(float x, float y, int columns) {
  // The float atan2 (glibc: within 2 ulp, 5e-7 rad) decides unless the point
  // lies within 1e-5 rad of a column edge, where the double one does: the
  // same column as from the double atan2 alone, at a fraction of its cost.
  const double edge_margin = 1e-5 / (2.0 * kPi) * columns;  // [columns]
  const double quick = (0.5 - static_cast<double>(std::atan2(y, x)) * (0.5 / kPi)) * columns;
  double u = quick;
  if (std::abs(quick - std::floor(quick + 0.5)) < edge_margin)
    u = 0.5 * (1.0 - std::atan2(static_cast<double>(y), static_cast<double>(x)) / kPi) * columns;
  return std::clamp(static_cast<int>(std::floor(u)), 0, columns - 1);
}

RangeImage project_scan(const LabelledCloud& cloud, std::span<const std::int16_t> rings, int beams,
                        const ProjectionSpec& spec) {
  const RowAssignment rows =
      spec.row_mode == RowMode::kRing ? rows_by_ring(cloud, rings, beams) : rows_by_elevation(cloud, spec);
  RangeImage image;
  image.rows = rows.rows;
  image.cols = spec.columns;
  image.channels = static_cast<int>(spec.channels.size());
  const std::size_t pixels = static_cast<std::size_t>(image.rows) * static_cast<std::size_t>(image.cols);
  image.range.assign(pixels, -1.0f);
  image.shown.assign(pixels, -1);
  image.point_pixel.assign(cloud.size(), -1);

  // Each pixel keeps its closest point (the first of equally close ones).
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (rows.row[i] < 0) continue;
    const Eigen::Vector3f& p = cloud.points[i];
    const float r = p.norm();
    if (!(r > 0.0f) || !std::isfinite(r)) continue;
    const auto pixel = static_cast<std::int32_t>(rows.row[i] * image.cols + projection_column(p.x(), p.y(), image.cols));
    image.point_pixel[i] = pixel;
    if (image.shown[pixel] < 0 || r < image.range[pixel]) {
      image.range[pixel] = r;
      image.shown[pixel] = static_cast<std::int32_t>(i);
    }
  }

  fill_channels(image, cloud, spec);
  return image;
}

}  // namespace saloam
