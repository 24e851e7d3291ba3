#include "saloam/mapping/map_render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/viz/canvas.hpp"

namespace saloam {
namespace {
constexpr float kInf = std::numeric_limits<float>::infinity();
}  // namespace

TopDownCanvas::TopDownCanvas(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, const TopDownOptions& options)
    : options_(options), lo_(lo), hi_(hi.cwiseMax(lo + Eigen::Vector2d(1e-3, 1e-3))), zmin_(kInf), zmax_(-kInf) {
  const Eigen::Vector2d extent = hi_ - lo_;
  const int max_pixels = std::max(1, options.max_pixels);
  double mpp = options.metres_per_pixel > 0 ? options.metres_per_pixel : extent.maxCoeff() / max_pixels;
  mpp = std::max({mpp, extent.maxCoeff() / max_pixels, 0.02});
  stats_.metres_per_pixel = mpp;
  stats_.width = std::max(1, static_cast<int>(std::ceil(extent.x() / mpp)));
  stats_.height = std::max(1, static_cast<int>(std::ceil(extent.y() / mpp)));
  const auto n = static_cast<std::size_t>(stats_.width) * static_cast<std::size_t>(stats_.height);
  top_.assign(n, -kInf);
  bottom_.assign(n, kInf);
  label_.assign(n, 0);
}

Eigen::Vector2i TopDownCanvas::pixel(double x, double y) const {
  const double mpp = stats_.metres_per_pixel;
  return {static_cast<int>(std::floor((x - lo_.x()) / mpp)), static_cast<int>(std::floor((hi_.y() - y) / mpp))};
}

void TopDownCanvas::add(const Eigen::Vector3d& point, std::uint16_t label, bool labelled) {
  const Eigen::Vector2i px = pixel(point.x(), point.y());
  if (px.x() < 0 || px.y() < 0 || px.x() >= stats_.width || px.y() >= stats_.height) return;
  const std::size_t idx = static_cast<std::size_t>(px.y()) * static_cast<std::size_t>(stats_.width) + static_cast<std::size_t>(px.x());
  const auto z = static_cast<float>(point.z());
  if (z > top_[idx]) {
    top_[idx] = z;
    label_[idx] = labelled ? label : 0;
  }
  bottom_[idx] = std::min(bottom_[idx], z);
  zmin_ = std::min(zmin_, z);
  zmax_ = std::max(zmax_, z);
  any_labelled_ = any_labelled_ || labelled;
  ++stats_.points_drawn;
}

std::uint16_t TopDownCanvas::shown_label(double x, double y) const {
  const Eigen::Vector2i px = pixel(x, y);
  if (px.x() < 0 || px.y() < 0 || px.x() >= stats_.width || px.y() >= stats_.height) return 0;
  return label_[static_cast<std::size_t>(px.y()) * static_cast<std::size_t>(stats_.width) + static_cast<std::size_t>(px.x())];
}

void TopDownCanvas::add(const LabelledCloud& cloud) {
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    add(cloud.points[i].cast<double>(), cloud.has_labels ? cloud.label[i] : 0, cloud.has_labels);
  }
}

TopDownStats TopDownCanvas::save(const std::filesystem::path& png, const std::vector<Pose>& trajectory,
                                 const std::vector<WorldSegment>& links) const {
  const int width = stats_.width, height = stats_.height;
  RasterImage image(width, height, {18, 18, 22});
  const float zspan = std::max(zmax_ - zmin_, 1.0f);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t idx = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      if (!std::isfinite(top_[idx])) continue;
      Rgb c{0, 0, 0};
      if (!any_labelled_) {
        c = viridis((top_[idx] - zmin_) / zspan);
      } else {
        c = label_[idx] == cls::kUnlabeled ? Rgb{150, 150, 150} : class_color(label_[idx]);
      }
      // Relief: what stands higher over the lowest point of its pixel is brighter.
      const double relief = std::clamp((top_[idx] - bottom_[idx]) / 8.0, 0.0, 1.0);
      const double shade = 0.72 + 0.28 * relief;
      auto s = [&](std::uint8_t v) { return static_cast<std::uint8_t>(std::clamp(v * shade, 0.0, 255.0)); };
      image.set(x, y, {s(c.r), s(c.g), s(c.b)});
    }
  }
  if (options_.draw_trajectory && !trajectory.empty()) {
    const double mpp = stats_.metres_per_pixel;
    const int thickness = std::max(1, static_cast<int>(std::lround(0.5 / mpp)));
    for (std::size_t i = 1; i < trajectory.size(); ++i) {
      const auto a = pixel(trajectory[i - 1].translation().x(), trajectory[i - 1].translation().y());
      const auto b = pixel(trajectory[i].translation().x(), trajectory[i].translation().y());
      image.draw_line(a.x(), a.y(), b.x(), b.y(), {255, 255, 255}, thickness);
    }
    const int radius = std::max(3, static_cast<int>(std::lround(1.5 / mpp)));
    const auto end = pixel(trajectory.back().translation().x(), trajectory.back().translation().y());
    image.draw_disc(end.x(), end.y(), radius, {230, 0, 0});
    const auto start = pixel(trajectory.front().translation().x(), trajectory.front().translation().y());
    image.draw_disc(start.x(), start.y(), radius, {0, 230, 0});
  }
  const int link_thickness = std::max(1, static_cast<int>(std::lround(0.8 / stats_.metres_per_pixel)));
  for (const auto& [from, to] : links) {
    const auto a = pixel(from.x(), from.y());
    const auto b = pixel(to.x(), to.y());
    image.draw_line(a.x(), a.y(), b.x(), b.y(), {255, 150, 0}, link_thickness);
    image.draw_disc(a.x(), a.y(), link_thickness + 1, {255, 150, 0});
    image.draw_disc(b.x(), b.y(), link_thickness + 1, {255, 150, 0});
  }
  image.save_png(png);
  return stats_;
}

TopDownStats render_top_down(const std::filesystem::path& png, const LabelledCloud& map, const std::vector<Pose>& trajectory,
                             const TopDownOptions& options, const std::vector<WorldSegment>& links) {
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
  TopDownCanvas canvas(lo - Eigen::Vector2d(5, 5), hi + Eigen::Vector2d(5, 5), options);
  canvas.add(map);
  return canvas.save(png, trajectory, links);
}

}  // namespace saloam
