#pragma once
// PNG pictures with cairo: a `Plot` with data axes (trajectories, curves,
// scatter maps) and a `RasterImage` for per-pixel pictures (range images,
// bird's-eye maps). Keep drawing code here, out of the algorithms.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/semantic_classes.hpp"

namespace saloam {

/// Perceptually uniform colour map (viridis) for t in [0, 1].
Rgb viridis(double t);
/// Perceptually ordered "turbo"-like map for errors: blue (low) to red (high).
Rgb turbo(double t);

struct LegendEntry {
  std::string label;
  Rgb color;
};

/// A 2D plot in data coordinates. Set the data range, draw, then save.
class Plot {
 public:
  Plot(int width_px, int height_px);
  ~Plot();
  Plot(Plot&&) noexcept;
  Plot& operator=(Plot&&) noexcept;

  /// Data range shown; with equal_aspect one metre is as long on both axes
  /// (maps), the range is widened to fit. Call before drawing.
  void set_range(double xmin, double xmax, double ymin, double ymax, bool equal_aspect);
  /// Range fitted to the given points with a 5 % margin.
  void fit_range(const std::vector<Eigen::Vector2d>& points, bool equal_aspect);

  /// Pixel margins around the plot area (defaults 80, 30, 40, 60). Widen the
  /// right one (about 90) before a colorbar. Call before set_range/fit_range.
  void set_margins(int left, int right, int top, int bottom) {
    left_ = left;
    right_ = right;
    top_ = top;
    bottom_ = bottom;
  }

  void set_title(const std::string& title) { title_ = title; }
  void set_labels(const std::string& x_label, const std::string& y_label) {
    x_label_ = x_label;
    y_label_ = y_label;
  }

  void line(const std::vector<Eigen::Vector2d>& points, Rgb color, double width_px = 1.5, bool dashed = false);
  /// A line whose segments are coloured by `values` mapped through turbo over [vmin, vmax].
  void colored_line(const std::vector<Eigen::Vector2d>& points, const std::vector<double>& values, double vmin,
                    double vmax, double width_px = 2.5);
  void scatter(const std::vector<Eigen::Vector2d>& points, const std::vector<Rgb>& colors, double radius_px = 1.0);
  void marker(const Eigen::Vector2d& p, Rgb color, double radius_px, const std::string& label = "");
  void legend(const std::vector<LegendEntry>& entries);
  /// A vertical colour bar on the right for a colored_line.
  void colorbar(double vmin, double vmax, const std::string& label);

  /// Draws frame, grid, ticks, labels and title, then writes the PNG.
  void save_png(const std::filesystem::path& file);

  [[nodiscard]] Eigen::Vector2d to_pixel(const Eigen::Vector2d& p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string title_, x_label_, y_label_;
  double xmin_ = 0, xmax_ = 1, ymin_ = 0, ymax_ = 1;
  int width_, height_;
  int left_ = 80, right_ = 30, top_ = 40, bottom_ = 60;
};

/// An RGB image written pixel by pixel.
class RasterImage {
 public:
  RasterImage(int width_px, int height_px, Rgb background = {0, 0, 0});
  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  void set(int x, int y, Rgb c);
  [[nodiscard]] Rgb get(int x, int y) const;
  /// A straight line of the given thickness [px] (clipped to the image).
  void draw_line(int x0, int y0, int x1, int y1, Rgb c, int thickness = 1);
  /// A filled disc (clipped to the image).
  void draw_disc(int cx, int cy, int radius, Rgb c);
  /// Writes the PNG, optionally scaled by an integer factor (nearest neighbour).
  void save_png(const std::filesystem::path& file, int scale_x = 1, int scale_y = 1) const;

 private:
  int width_, height_;
  std::vector<Rgb> pixels_;
};

}  // namespace saloam
