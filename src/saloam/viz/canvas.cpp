#include "saloam/viz/canvas.hpp"

#include <cairo.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <ostream>
#include <stdexcept>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/output_file.hpp"

namespace saloam {
namespace {

Rgb lerp_table(const std::array<Rgb, 9>& table, double t) {
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * static_cast<double>(table.size() - 1);
  const auto i = std::min(static_cast<std::size_t>(t), table.size() - 2);
  const double f = t - static_cast<double>(i);
  auto mix = [&](std::uint8_t a, std::uint8_t b) {
    return static_cast<std::uint8_t>(std::lround(a + f * (static_cast<double>(b) - a)));
  };
  return {mix(table[i].r, table[i + 1].r), mix(table[i].g, table[i + 1].g), mix(table[i].b, table[i + 1].b)};
}

void set_color(cairo_t* cr, Rgb c, double alpha = 1.0) {
  cairo_set_source_rgba(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0, alpha);
}

/// A "nice" tick step (1, 2 or 5 times a power of ten) for about `target` ticks.
double nice_step(double span, int target) {
  const double raw = span / std::max(target, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * mag >= raw) return m * mag;
  }
  return 10.0 * mag;
}

std::string tick_label(double v, double step) {
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step)));
  return fmt::format("{:.{}f}", std::abs(v) < 1e-12 ? 0.0 : v, decimals);
}

cairo_status_t write_to_stream(void* closure, const unsigned char* data, unsigned int length) {
  auto& out = *static_cast<std::ostream*>(closure);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(length));
  return out ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

// Writes the surface as a PNG through an AtomicFile: complete or absent, every write checked.
void write_png(cairo_surface_t* surface, const std::filesystem::path& file) {
  AtomicFile out(file);
  const cairo_status_t status = cairo_surface_write_to_png_stream(surface, write_to_stream, &out.stream());
  if (status == CAIRO_STATUS_WRITE_ERROR) out.flush();  // throws with the system's reason
  if (status != CAIRO_STATUS_SUCCESS) throw InputError(file, std::string("PNG write failed: ") + cairo_status_to_string(status));
  out.commit();
}

}  // namespace

Rgb viridis(double t) {
  static constexpr std::array<Rgb, 9> kTable{{{68, 1, 84}, {71, 44, 122}, {59, 81, 139}, {44, 113, 142}, {33, 144, 141},
                                              {39, 173, 129}, {92, 200, 99}, {170, 220, 50}, {253, 231, 37}}};
  return lerp_table(kTable, t);
}

Rgb turbo(double t) {
  static constexpr std::array<Rgb, 9> kTable{{{48, 18, 59}, {65, 69, 171}, {57, 162, 252}, {27, 229, 181}, {116, 254, 93},
                                              {201, 239, 52}, {251, 185, 56}, {245, 105, 24}, {122, 4, 3}}};
  return lerp_table(kTable, t);
}

struct Plot::Impl {
  cairo_surface_t* surface = nullptr;
  cairo_t* cr = nullptr;
  ~Impl() {
    if (cr) cairo_destroy(cr);
    if (surface) cairo_surface_destroy(surface);
  }
};

Plot::Plot(int width_px, int height_px) : impl_(std::make_unique<Impl>()), width_(width_px), height_(height_px) {
  impl_->surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width_, height_);
  impl_->cr = cairo_create(impl_->surface);
  cairo_set_source_rgb(impl_->cr, 1, 1, 1);
  cairo_paint(impl_->cr);
  cairo_select_font_face(impl_->cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
}

Plot::~Plot() = default;
Plot::Plot(Plot&&) noexcept = default;
Plot& Plot::operator=(Plot&&) noexcept = default;

void Plot::set_range(double xmin, double xmax, double ymin, double ymax, bool equal_aspect) {
  if (!(xmax > xmin)) xmax = xmin + 1.0;
  if (!(ymax > ymin)) ymax = ymin + 1.0;
  if (equal_aspect) {
    const double w_px = width_ - left_ - right_, h_px = height_ - top_ - bottom_;
    const double scale = std::max((xmax - xmin) / w_px, (ymax - ymin) / h_px);
    const double cx = 0.5 * (xmin + xmax), cy = 0.5 * (ymin + ymax);
    xmin = cx - 0.5 * scale * w_px;
    xmax = cx + 0.5 * scale * w_px;
    ymin = cy - 0.5 * scale * h_px;
    ymax = cy + 0.5 * scale * h_px;
  }
  xmin_ = xmin;
  xmax_ = xmax;
  ymin_ = ymin;
  ymax_ = ymax;
}

void Plot::fit_range(const std::vector<Eigen::Vector2d>& points, bool equal_aspect) {
  if (points.empty()) return;
  Eigen::Vector2d lo = points.front(), hi = points.front();
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector2d pad = 0.05 * (hi - lo).cwiseMax(Eigen::Vector2d(1e-6, 1e-6));
  set_range(lo.x() - pad.x(), hi.x() + pad.x(), lo.y() - pad.y(), hi.y() + pad.y(), equal_aspect);
}

Eigen::Vector2d Plot::to_pixel(const Eigen::Vector2d& p) const {
  const double u = left_ + (p.x() - xmin_) / (xmax_ - xmin_) * (width_ - left_ - right_);
  const double v = height_ - bottom_ - (p.y() - ymin_) / (ymax_ - ymin_) * (height_ - top_ - bottom_);
  return {u, v};
}

void Plot::line(const std::vector<Eigen::Vector2d>& points, Rgb color, double width_px, bool dashed) {
  if (points.size() < 2) return;
  cairo_t* cr = impl_->cr;
  cairo_save(cr);
  set_color(cr, color);
  cairo_set_line_width(cr, width_px);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  if (dashed) {
    const double dash[] = {6.0, 4.0};
    cairo_set_dash(cr, dash, 2, 0);
  }
  const auto p0 = to_pixel(points.front());
  cairo_move_to(cr, p0.x(), p0.y());
  for (std::size_t i = 1; i < points.size(); ++i) {
    const auto p = to_pixel(points[i]);
    cairo_line_to(cr, p.x(), p.y());
  }
  cairo_stroke(cr);
  cairo_restore(cr);
}

void Plot::colored_line(const std::vector<Eigen::Vector2d>& points, const std::vector<double>& values, double vmin,
                        double vmax, double width_px) {
  cairo_t* cr = impl_->cr;
  cairo_save(cr);
  cairo_set_line_width(cr, width_px);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  const double span = vmax > vmin ? vmax - vmin : 1.0;
  for (std::size_t i = 1; i < points.size() && i < values.size(); ++i) {
    set_color(cr, turbo((values[i] - vmin) / span));
    const auto a = to_pixel(points[i - 1]);
    const auto b = to_pixel(points[i]);
    cairo_move_to(cr, a.x(), a.y());
    cairo_line_to(cr, b.x(), b.y());
    cairo_stroke(cr);
  }
  cairo_restore(cr);
}

void Plot::scatter(const std::vector<Eigen::Vector2d>& points, const std::vector<Rgb>& colors, double radius_px) {
  cairo_t* cr = impl_->cr;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto p = to_pixel(points[i]);
    set_color(cr, i < colors.size() ? colors[i] : Rgb{0, 0, 0});
    cairo_rectangle(cr, p.x() - radius_px, p.y() - radius_px, 2 * radius_px, 2 * radius_px);
    cairo_fill(cr);
  }
}

void Plot::marker(const Eigen::Vector2d& p, Rgb color, double radius_px, const std::string& label) {
  cairo_t* cr = impl_->cr;
  const auto q = to_pixel(p);
  set_color(cr, color);
  cairo_arc(cr, q.x(), q.y(), radius_px, 0, 2 * M_PI);
  cairo_fill(cr);
  if (!label.empty()) {
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_font_size(cr, 12);
    cairo_move_to(cr, q.x() + radius_px + 3, q.y() - radius_px - 2);
    cairo_show_text(cr, label.c_str());
  }
}

void Plot::legend(const std::vector<LegendEntry>& entries) {
  cairo_t* cr = impl_->cr;
  cairo_set_font_size(cr, 13);
  double max_w = 0;
  for (const auto& e : entries) {
    cairo_text_extents_t ext;
    cairo_text_extents(cr, e.label.c_str(), &ext);
    max_w = std::max(max_w, ext.x_advance);
  }
  const double x0 = left_ + 10, y0 = top_ + 10, row = 18;
  cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
  cairo_rectangle(cr, x0, y0, max_w + 44, row * static_cast<double>(entries.size()) + 8);
  cairo_fill(cr);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const double y = y0 + 4 + row * static_cast<double>(i);
    set_color(cr, entries[i].color);
    cairo_rectangle(cr, x0 + 6, y + 4, 22, 8);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_move_to(cr, x0 + 34, y + 13);
    cairo_show_text(cr, entries[i].label.c_str());
  }
}

void Plot::colorbar(double vmin, double vmax, const std::string& label) {
  cairo_t* cr = impl_->cr;
  const double x = width_ - right_ + 12, w = 16, y0 = top_, h = height_ - top_ - bottom_;
  for (int i = 0; i < static_cast<int>(h); ++i) {
    set_color(cr, turbo(1.0 - i / h));
    cairo_rectangle(cr, x, y0 + i, w, 1.5);
    cairo_fill(cr);
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_font_size(cr, 11);
  const double step = nice_step(vmax - vmin, 5);
  for (double v = std::ceil(vmin / step) * step; v <= vmax + 1e-9; v += step) {
    const double y = y0 + h * (1.0 - (v - vmin) / (vmax - vmin));
    cairo_move_to(cr, x + w + 3, y + 4);
    cairo_show_text(cr, tick_label(v, step).c_str());
  }
  cairo_save(cr);
  cairo_move_to(cr, width_ - 8, y0 + h / 2 + 40);
  cairo_rotate(cr, -M_PI / 2);
  cairo_show_text(cr, label.c_str());
  cairo_restore(cr);
}

void Plot::save_png(const std::filesystem::path& file) {
  cairo_t* cr = impl_->cr;
  const double x0 = left_, x1 = width_ - right_, y0 = top_, y1 = height_ - bottom_;
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, x0, y0, x1 - x0, y1 - y0);
  cairo_stroke(cr);
  cairo_set_font_size(cr, 11);
  const double sx = nice_step(xmax_ - xmin_, 8), sy = nice_step(ymax_ - ymin_, 8);
  for (double v = std::ceil(xmin_ / sx) * sx; v <= xmax_; v += sx) {
    const double u = to_pixel({v, ymin_}).x();
    cairo_set_source_rgba(cr, 0, 0, 0, 0.12);
    cairo_move_to(cr, u, y0);
    cairo_line_to(cr, u, y1);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    const auto text = tick_label(v, sx);
    cairo_text_extents_t ext;
    cairo_text_extents(cr, text.c_str(), &ext);
    cairo_move_to(cr, u - ext.width / 2, y1 + 16);
    cairo_show_text(cr, text.c_str());
  }
  for (double v = std::ceil(ymin_ / sy) * sy; v <= ymax_; v += sy) {
    const double w = to_pixel({xmin_, v}).y();
    cairo_set_source_rgba(cr, 0, 0, 0, 0.12);
    cairo_move_to(cr, x0, w);
    cairo_line_to(cr, x1, w);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    const auto text = tick_label(v, sy);
    cairo_text_extents_t ext;
    cairo_text_extents(cr, text.c_str(), &ext);
    cairo_move_to(cr, x0 - ext.width - 6, w + 4);
    cairo_show_text(cr, text.c_str());
  }
  cairo_set_font_size(cr, 13);
  cairo_text_extents_t ext;
  cairo_text_extents(cr, x_label_.c_str(), &ext);
  cairo_move_to(cr, (x0 + x1) / 2 - ext.width / 2, height_ - 18);
  cairo_show_text(cr, x_label_.c_str());
  cairo_save(cr);
  cairo_text_extents(cr, y_label_.c_str(), &ext);
  cairo_move_to(cr, 22, (y0 + y1) / 2 + ext.width / 2);
  cairo_rotate(cr, -M_PI / 2);
  cairo_show_text(cr, y_label_.c_str());
  cairo_restore(cr);
  cairo_set_font_size(cr, 15);
  cairo_text_extents(cr, title_.c_str(), &ext);
  cairo_move_to(cr, width_ / 2.0 - ext.width / 2, 26);
  cairo_show_text(cr, title_.c_str());

  cairo_surface_flush(impl_->surface);
  write_png(impl_->surface, file);
}

RasterImage::RasterImage(int width_px, int height_px, Rgb background)
    : width_(width_px), height_(height_px), pixels_(static_cast<std::size_t>(width_px) * height_px, background) {
  if (width_px <= 0 || height_px <= 0) throw std::invalid_argument("RasterImage: size must be positive");
}

void RasterImage::set(int x, int y, Rgb c) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
  pixels_[static_cast<std::size_t>(y) * width_ + x] = c;
}

void RasterImage::draw_disc(int cx, int cy, int radius, Rgb c) {
  for (int dy = -radius; dy <= radius; ++dy) {
    for (int dx = -radius; dx <= radius; ++dx) {
      if (dx * dx + dy * dy <= radius * radius) set(cx + dx, cy + dy, c);
    }
  }
}

void RasterImage::draw_line(int x0, int y0, int x1, int y1, Rgb c, int thickness) {
  // Sample the segment at sub-pixel steps; each sample stamps a disc.
  const int steps = std::max({std::abs(x1 - x0), std::abs(y1 - y0), 1});
  const int radius = std::max(thickness / 2, 0);
  for (int i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) / steps;
    const int x = static_cast<int>(std::lround(x0 + t * (x1 - x0)));
    const int y = static_cast<int>(std::lround(y0 + t * (y1 - y0)));
    if (radius == 0) {
      set(x, y, c);
    } else {
      draw_disc(x, y, radius, c);
    }
  }
}

Rgb RasterImage::get(int x, int y) const { return pixels_.at(static_cast<std::size_t>(y) * width_ + x); }

void RasterImage::save_png(const std::filesystem::path& file, int scale_x, int scale_y) const {
  scale_x = std::max(scale_x, 1);
  scale_y = std::max(scale_y, 1);
  const int w = width_ * scale_x, h = height_ * scale_y;
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  const int stride = cairo_image_surface_get_stride(surface);
  cairo_surface_flush(surface);
  unsigned char* data = cairo_image_surface_get_data(surface);
  for (int y = 0; y < h; ++y) {
    auto* row = reinterpret_cast<std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
    for (int x = 0; x < w; ++x) {
      const Rgb c = pixels_[static_cast<std::size_t>(y / scale_y) * width_ + x / scale_x];
      row[x] = (std::uint32_t{c.r} << 16) | (std::uint32_t{c.g} << 8) | c.b;
    }
  }
  cairo_surface_mark_dirty(surface);
  const std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> owned(surface, cairo_surface_destroy);
  write_png(surface, file);
}

}  // namespace saloam
