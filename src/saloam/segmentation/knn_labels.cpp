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
  std::uint16_t order;  ///< position in the window: among equal distances the earlier ranks first
};

/// The ranking of the vote: nearer first, then earlier in the window.
bool nearer(const Candidate& a, const Candidate& b) {
  return a.distance < b.distance || (a.distance == b.distance && a.order < b.order);
}

}  // namespace

std::vector<float> point_ranges(const LabelledCloud& cloud) {
  std::vector<float> r(cloud.size());
  std::transform(cloud.points.begin(), cloud.points.end(), r.begin(), [](const Eigen::Vector3f& p) { return p.norm(); });
  return r;
}

namespace {

constexpr int kMaxWindow = 15;

/// The pixels of the window around one point: its rows (clipped to the
/// image) and its columns (wrapped around in azimuth).
struct Window {
  int first_row = 0, last_row = 0;
  std::array<int, kMaxWindow> cols{};
  int half = 0;
};

/// Column c of an image `cols` wide, wrapped around in azimuth (the division
/// only at the seam).
int wrapped_column(int c, int cols) {
  if (c >= 0 && c < cols) return c;
  c %= cols;
  return c < 0 ? c + cols : c;
}

Window window_at(const RangeImage& image, int row, int col, int half) {
  Window w;
  w.half = half;
  w.first_row = std::max(row - half, 0);
  w.last_row = std::min(row + half, image.rows - 1);
  for (int dx = -half; dx <= half; ++dx) w.cols[static_cast<std::size_t>(dx + half)] = wrapped_column(col + dx, image.cols);
  return w;
}

constexpr std::int16_t kNoPoint = -1, kMixed = -2;

/// For every pixel: the class all points within `half` columns of it (same
/// row, wrapping around in azimuth) show, kMixed when they differ, kNoPoint
/// when there is none.
std::vector<std::int16_t> row_classes(const RangeImage& image, const std::vector<std::int16_t>& pixel_class, int half) {
  std::vector<std::int16_t> out(image.pixels(), kNoPoint);
  for (int y = 0; y < image.rows; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(image.cols);
    for (int x = 0; x < image.cols; ++x) {
      std::int16_t c = kNoPoint;
      for (int dx = -half; dx <= half && c != kMixed; ++dx) {
        const std::size_t p = row + static_cast<std::size_t>(wrapped_column(x + dx, image.cols));
        if (image.range[p] < 0) continue;
        c = c == kNoPoint || c == pixel_class[p] ? pixel_class[p] : kMixed;
      }
      out[row + static_cast<std::size_t>(x)] = c;
    }
  }
  return out;
}

/// For every pixel: 1 when every point in the window around it shows its
/// class (then every vote of a point in it goes to that class: the point's
/// own pixel always votes).
std::vector<std::uint8_t> uniform_windows(const RangeImage& image, const std::vector<std::int16_t>& pixel_class, int half) {
  const std::vector<std::int16_t> rows = row_classes(image, pixel_class, half);
  std::vector<std::uint8_t> out(image.pixels(), 0);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const auto p = static_cast<std::size_t>(y * image.cols + x);
      if (image.range[p] < 0) continue;
      bool uniform = true;
      for (int yy = std::max(y - half, 0); yy <= std::min(y + half, image.rows - 1) && uniform; ++yy) {
        const std::int16_t c = rows[static_cast<std::size_t>(yy * image.cols + x)];
        uniform = c == kNoPoint || c == pixel_class[p];
      }
      out[p] = uniform;
    }
  return out;
}

/// The pixels of a point's window that can vote: those showing a point within
/// the cutoff of its range (distance = |range difference| x the offset's
/// weight; the point's own pixel at distance 0), in window order. Only they
/// can vote: every farther pixel ranks behind all of them.
struct Voters {
  std::array<Candidate, kMaxWindow * kMaxWindow> near;  // [0, n) is set
  std::size_t n = 0;
  bool one_label = true;  ///< all of them show one class
};

struct VoteWindow {
  int half = 0, side = 0;
  std::vector<float> weight;  ///< per window offset, row-major
  float cutoff = 0.0f;
};

Voters voters(const RangeImage& image, const std::vector<std::int16_t>& pixel_class, const VoteWindow& vw,
              std::int32_t pixel, float range) {
  Voters v;
  const int row = pixel / image.cols;
  const Window w = window_at(image, row, pixel % image.cols, vw.half);
  for (int y = w.first_row; y <= w.last_row; ++y)
    for (int j = 0; j < vw.side; ++j) {
      const auto p = static_cast<std::size_t>(y * image.cols + w.cols[static_cast<std::size_t>(j)]);
      const bool self = static_cast<std::int32_t>(p) == pixel;
      if (!self && image.range[p] < 0) continue;
      const float wt = vw.weight[static_cast<std::size_t>((y - row + vw.half) * vw.side + j)];
      const float distance = self ? 0.0f : std::abs(image.range[p] - range) * wt;
      if (!(distance <= vw.cutoff)) continue;
      v.near[v.n] = {distance, pixel_class[p], static_cast<std::uint16_t>(v.n)};
      ++v.n;
      v.one_label = v.one_label && pixel_class[p] == v.near[0].label;
    }
  return v;
}

/// The class most of the k nearest voters show (the lowest class on a tie;
/// class 0 and classes beyond the network's do not count), `own` when none
/// counts. The k nearest are selected in place (their order among
/// themselves does not matter to the count). `votes` is scratch space, one
/// per class.
std::int16_t voted_class(Voters& v, std::size_t k, int classes, std::int16_t own, std::vector<int>& votes) {
  const auto counts = [classes](std::int16_t c) { return c > 0 && c < classes; };
  if (v.n == 0) return own;
  if (v.one_label) return counts(v.near[0].label) ? v.near[0].label : own;
  const auto first = v.near.begin();
  const std::size_t voting = std::min(k, v.n);
  if (voting < v.n) std::nth_element(first, first + static_cast<std::ptrdiff_t>(voting), first + static_cast<std::ptrdiff_t>(v.n), nearer);
  std::fill(votes.begin(), votes.end(), 0);
  for (std::size_t j = 0; j < voting; ++j)
    if (counts(v.near[j].label)) ++votes[static_cast<std::size_t>(v.near[j].label)];
  const auto best = std::max_element(votes.begin() + 1, votes.end());
  return *best > 0 ? static_cast<std::int16_t>(best - votes.begin()) : own;
}

}  // namespace

std::vector<std::int16_t> point_classes(const RangeImage& image, const std::vector<std::int16_t>& pixel_class,
                                        const std::vector<float>& point_range, int classes,
                                        const KnnOptions& options) {
  VoteWindow vw;
  vw.half = std::min(options.window, kMaxWindow) / 2;
  vw.side = 2 * vw.half + 1;
  vw.weight = inverse_gaussian(vw.side, options.sigma);
  vw.cutoff = static_cast<float>(options.cutoff);
  const auto k = static_cast<std::size_t>(std::max(options.k, 1));
  std::vector<std::int16_t> out(image.point_pixel.size(), 0);
  std::vector<int> votes(static_cast<std::size_t>(classes));
  const std::vector<std::uint8_t> uniform = uniform_windows(image, pixel_class, vw.half);
  const auto vote = [&](std::int32_t pixel, std::size_t i, std::int16_t own) {
    Voters v = voters(image, pixel_class, vw, pixel, point_range[i]);
    return voted_class(v, k, classes, own, votes);
  };
  for (std::size_t i = 0; i < image.point_pixel.size(); ++i) {
    const std::int32_t pixel = image.point_pixel[i];
    if (pixel < 0) continue;
    const std::int16_t own = pixel_class[static_cast<std::size_t>(pixel)];
    out[i] = own > 0 && own < classes && uniform[static_cast<std::size_t>(pixel)]
                 ? own
                 : vote(pixel, i, own);
  }
  return out;
}

}  // namespace saloam
