#include "saloam/segmentation/knn_labels.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace saloam {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// 1 - g(offset) for every window position, row-major (RangeNet++'s weights:
/// g is the unnormalised 2D Gaussian density 1 / (2 pi s^2) exp(-d^2 / (2 s^2))).
std::vector<float> inverse_gaussian(int window, double sigma) {
  std::vector<float> w(static_cast<std::size_t>(window * window));
  const double mean = 0.5 * (window - 1), variance = sigma * sigma;
  for (int dy = 0; dy < window; ++dy)
    for (int dx = 0; dx < window; ++dx) {
      const double d2 = (dx - mean) * (dx - mean) + (dy - mean) * (dy - mean);
      w[static_cast<std::size_t>(dy * window + dx)] =
          static_cast<float>(1.0 - std::exp(-d2 / (2 * variance)) / (2 * kPi * variance));
    }
  return w;
}

struct Candidate {
  float distance;
  std::int16_t label;
};

}  // namespace

std::vector<float> point_ranges(const LabelledCloud& cloud) {
  std::vector<float> r(cloud.size());
  std::transform(cloud.points.begin(), cloud.points.end(), r.begin(), [](const Eigen::Vector3f& p) { return p.norm(); });
  return r;
}

namespace {

/// True when every pixel with a point in the window around (row, col) shows
/// `label`: then every vote goes to it (the point's own pixel always votes).
bool uniform_window(const RangeImage& image, const std::vector<std::int16_t>& pixel_class, int row, int col, int half,
                    std::int16_t label) {
  for (int y = std::max(row - half, 0); y <= std::min(row + half, image.rows - 1); ++y)
    for (int dx = -half; dx <= half; ++dx) {
      const auto p = static_cast<std::size_t>(y * image.cols + (col + dx + image.cols) % image.cols);
      if (image.range[p] >= 0 && pixel_class[p] != label) return false;
    }
  return true;
}

}  // namespace

std::vector<std::int16_t> point_classes(const RangeImage& image, const std::vector<std::int16_t>& pixel_class,
                                        const std::vector<float>& point_range, int classes,
                                        const KnnOptions& options) {
  const int half = options.window / 2;
  const std::vector<float> weight = inverse_gaussian(options.window, options.sigma);
  const auto cutoff = static_cast<float>(options.cutoff);
  const std::size_t k = static_cast<std::size_t>(std::max(options.k, 1));
  std::vector<std::int16_t> out(image.point_pixel.size(), 0);
  std::vector<Candidate> candidates;
  candidates.reserve(weight.size());
  std::vector<int> votes(static_cast<std::size_t>(classes));

  for (std::size_t i = 0; i < image.point_pixel.size(); ++i) {
    const std::int32_t pixel = image.point_pixel[i];
    if (pixel < 0) continue;
    const int row = pixel / image.cols, col = pixel % image.cols;
    const std::int16_t own = pixel_class[static_cast<std::size_t>(pixel)];
    if (own > 0 && own < classes && uniform_window(image, pixel_class, row, col, half, own)) {
      out[i] = own;
      continue;
    }
    const float r = point_range[i];
    candidates.clear();
    for (int dy = -half; dy <= half; ++dy) {
      const int y = row + dy;
      if (y < 0 || y >= image.rows) continue;
      for (int dx = -half; dx <= half; ++dx) {
        const int x = (col + dx + image.cols) % image.cols;
        const auto p = static_cast<std::size_t>(y * image.cols + x);
        const bool self = dx == 0 && dy == 0;
        if (!self && image.range[p] < 0) continue;
        const float w = weight[static_cast<std::size_t>((dy + half) * options.window + dx + half)];
        candidates.push_back({self ? 0.0f : std::abs(image.range[p] - r) * w, pixel_class[p]});
      }
    }
    const std::size_t n = std::min(k, candidates.size());
    std::partial_sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(n), candidates.end(),
                      [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
    std::fill(votes.begin(), votes.end(), 0);
    for (std::size_t j = 0; j < n; ++j)
      if (candidates[j].distance <= cutoff && candidates[j].label > 0 && candidates[j].label < classes)
        ++votes[static_cast<std::size_t>(candidates[j].label)];
    const auto best = std::max_element(votes.begin() + 1, votes.end());
    out[i] = *best > 0 ? static_cast<std::int16_t>(best - votes.begin()) : own;
  }
  return out;
}

}  // namespace saloam
