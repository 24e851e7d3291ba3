#include "saloam/viz/range_image.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/viz/canvas.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

void render_range_image(const LabelledCloud& cloud, const fs::path& png, const std::vector<double>& elevation_deg,
                        int columns) {
  if (elevation_deg.empty() || columns <= 0) throw std::invalid_argument("render_range_image: no beams or no columns");
  const int rows = static_cast<int>(elevation_deg.size());
  // Beam row from the elevation: nearest beam.
  auto row_of = [&](double elevation) {
    int best = 0;
    double best_d = 1e9;
    for (int b = 0; b < rows; ++b) {
      const double d = std::abs(elevation_deg[static_cast<std::size_t>(b)] - elevation);
      if (d < best_d) {
        best_d = d;
        best = b;
      }
    }
    return best_d < 1.0 ? best : -1;
  };
  RasterImage img(columns, 2 * rows + 2, {0, 0, 0});
  std::vector<float> depth(static_cast<std::size_t>(columns) * static_cast<std::size_t>(rows), std::numeric_limits<float>::infinity());
  for (std::size_t k = 0; k < cloud.size(); ++k) {
    const Eigen::Vector3f& p = cloud.points[k];
    const double r = p.norm();
    if (r < 1e-3) continue;
    const double el = std::atan2(p.z(), std::hypot(p.x(), p.y())) * 180.0 / kPi;
    const int row = row_of(el);
    if (row < 0) continue;
    // Front in the middle, left of the car on the left of the picture.
    const double az = std::atan2(p.y(), p.x());
    int col = static_cast<int>((0.5 - az / (2 * kPi)) * columns);
    col = std::clamp(col, 0, columns - 1);
    const std::size_t idx = static_cast<std::size_t>(row) * static_cast<std::size_t>(columns) + static_cast<std::size_t>(col);
    if (r >= depth[idx]) continue;
    depth[idx] = static_cast<float>(r);
    const std::uint16_t lab = cloud.has_labels ? cloud.label[k] : 0;
    img.set(col, row, lab == 0 ? Rgb{160, 160, 160} : class_color(lab));
    img.set(col, rows + 2 + row, viridis(1.0 - std::min(1.0, std::log1p(r) / std::log1p(80.0))));
  }
  img.save_png(png, 1, 4);
}

}  // namespace saloam
