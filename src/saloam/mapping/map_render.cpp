#include "saloam/mapping/map_render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/viz/canvas.hpp"

namespace saloam {

void render_top_down(const std::filesystem::path& png, const LabelledCloud& map, const std::vector<Pose>& trajectory,
                     const TopDownOptions& options) {
  Eigen::Vector2d lo(std::numeric_limits<double>::max(), std::numeric_limits<double>::max());
  Eigen::Vector2d hi = -lo;
  for (const auto& p : map.points) {
    lo = lo.cwiseMin(p.head<2>().cast<double>());
    hi = hi.cwiseMax(p.head<2>().cast<double>());
  }
  for (const auto& T : trajectory) {
    lo = lo.cwiseMin(T.translation().head<2>());
    hi = hi.cwiseMax(T.translation().head<2>());
  }
  if (map.empty() && trajectory.empty()) lo = hi = Eigen::Vector2d::Zero();
  lo -= Eigen::Vector2d(5, 5);
  hi += Eigen::Vector2d(5, 5);
  const Eigen::Vector2d extent = hi - lo;
  const double mpp = options.metres_per_pixel > 0 ? options.metres_per_pixel
                                                  : std::max(extent.maxCoeff() / options.max_pixels, 0.05);
  const int width = std::max(1, static_cast<int>(std::ceil(extent.x() / mpp)));
  const int height = std::max(1, static_cast<int>(std::ceil(extent.y() / mpp)));
  auto to_px = [&](double x, double y) {
    return Eigen::Vector2i(static_cast<int>((x - lo.x()) / mpp), height - 1 - static_cast<int>((y - lo.y()) / mpp));
  };

  // Height buffer: the highest point per pixel wins.
  std::vector<float> top(static_cast<std::size_t>(width) * height, -std::numeric_limits<float>::infinity());
  std::vector<std::uint16_t> label(top.size(), 0);
  float zmin = std::numeric_limits<float>::max(), zmax = -zmin;
  for (std::size_t i = 0; i < map.size(); ++i) {
    const auto& p = map.points[i];
    const auto px = to_px(p.x(), p.y());
    if (px.x() < 0 || px.y() < 0 || px.x() >= width || px.y() >= height) continue;
    const std::size_t idx = static_cast<std::size_t>(px.y()) * width + px.x();
    if (p.z() > top[idx]) {
      top[idx] = p.z();
      label[idx] = map.label[i];
    }
    zmin = std::min(zmin, p.z());
    zmax = std::max(zmax, p.z());
  }
  RasterImage image(width, height, {20, 20, 24});
  const float zspan = std::max(zmax - zmin, 1.0f);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t idx = static_cast<std::size_t>(y) * width + x;
      if (!std::isfinite(top[idx])) continue;
      Rgb c = map.has_labels ? class_color(label[idx]) : viridis((top[idx] - zmin) / zspan);
      if (map.has_labels && label[idx] == cls::kUnlabeled) c = {120, 120, 120};
      // Height shading: higher is brighter, so buildings stand out from the road.
      const double shade = 0.65 + 0.35 * std::clamp((top[idx] - zmin) / zspan * 2.0f, 0.0f, 1.0f);
      image.set(x, y, {static_cast<std::uint8_t>(c.r * shade), static_cast<std::uint8_t>(c.g * shade),
                       static_cast<std::uint8_t>(c.b * shade)});
    }
  }
  if (options.draw_trajectory && trajectory.size() > 1) {
    const int radius = std::max(1, static_cast<int>(std::lround(0.6 / mpp)));
    for (std::size_t i = 1; i < trajectory.size(); ++i) {
      const auto a = to_px(trajectory[i - 1].translation().x(), trajectory[i - 1].translation().y());
      const auto b = to_px(trajectory[i].translation().x(), trajectory[i].translation().y());
      image.draw_line(a.x(), a.y(), b.x(), b.y(), {255, 255, 255}, radius);
    }
    const auto start = to_px(trajectory.front().translation().x(), trajectory.front().translation().y());
    image.draw_disc(start.x(), start.y(), 4 * radius, {0, 255, 0});
  }
  image.save_png(png);
}

}  // namespace saloam
