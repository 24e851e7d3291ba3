#include "saloam/segmentation/segmenter.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/odometry/features.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

using OpenNetwork = NetworkRunner* (*)(const NetworkSpec&, std::string&);

/// The plugin's entry point, loaded once per plugin path and never unloaded
/// (libtorch does not support being unloaded).
OpenNetwork plugin_entry(const fs::path& plugin) {
  static std::mutex mutex;
  static std::map<fs::path, OpenNetwork> loaded;
  const std::lock_guard lock(mutex);
  if (const auto it = loaded.find(plugin); it != loaded.end()) return it->second;
  std::error_code error;
  if (!fs::is_regular_file(plugin, error))
    throw InputError(plugin, "not found: segmentation needs the network plugin, which is built only with libtorch "
                             "(install libtorch-dev, e.g. scripts/install_deps.sh, and rebuild)");
  void* handle = dlopen(plugin.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) throw InputError(plugin, fmt::format("cannot be loaded: {}", dlerror()));
  auto entry = reinterpret_cast<OpenNetwork>(dlsym(handle, "saloam_open_network"));
  if (entry == nullptr) throw InputError(plugin, "is not saloam's network plugin (no saloam_open_network)");
  loaded.emplace(plugin, entry);
  return entry;
}

std::string beam_list(const std::vector<int>& beams) { return fmt::format("{}", fmt::join(beams, "/")); }

}  // namespace

void load_segmentation_plugin(const fs::path& plugin) { plugin_entry(plugin); }

namespace {

/// Median elevation [rad] of each ring (every 4th point), NaN for an empty ring.
std::vector<double> ring_elevations(const LabelledCloud& cloud, const std::vector<std::vector<std::uint32_t>>& rings) {
  std::vector<double> out;
  std::vector<double> e;
  for (const auto& ring : rings) {
    e.clear();
    for (std::size_t k = 0; k < ring.size(); k += 4) {
      const Eigen::Vector3f& p = cloud.points[ring[k]];
      e.push_back(std::atan2(static_cast<double>(p.z()), std::hypot(static_cast<double>(p.x()), static_cast<double>(p.y()))));
    }
    if (e.empty()) {
      out.push_back(std::nan(""));
      continue;
    }
    std::nth_element(e.begin(), e.begin() + static_cast<std::ptrdiff_t>(e.size() / 2), e.end());
    out.push_back(e[e.size() / 2]);
  }
  return out;
}

/// The median of the gaps near gap k (up to four on each side, k itself
/// left out): the local ring spacing (the HDL-64E's two blocks differ).
double local_spacing(const std::vector<double>& gaps, std::size_t k) {
  std::vector<double> near;
  for (std::size_t j = k >= 4 ? k - 4 : 0; j < std::min(gaps.size(), k + 5); ++j)
    if (j != k && std::isfinite(gaps[j]) && gaps[j] > 0) near.push_back(gaps[j]);
  if (near.empty()) return std::nan("");
  std::nth_element(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(near.size() / 2), near.end());
  return near[near.size() / 2];
}

/// Row of each found ring in an image of `rows` rows (rows >= found rings):
/// a ring that returned nothing (the sky above a top beam, a lost beam)
/// leaves a gap; a gap of about n + 1 local ring spacings gets n empty rows
/// (widest gaps first), and what is still missing goes above the top ring.
std::vector<int> ring_rows(const std::vector<double>& elevation, int rows) {
  const int found = static_cast<int>(elevation.size());
  std::vector<double> gaps, spacing;  // gap k lies between rings k and k + 1
  for (int k = 1; k < found; ++k) gaps.push_back(elevation[k - 1] - elevation[k]);
  for (std::size_t k = 0; k < gaps.size(); ++k) spacing.push_back(local_spacing(gaps, k));
  std::vector<int> extra(static_cast<std::size_t>(found), 0);  // empty rows inserted above ring k
  int missing = rows - found;
  for (; missing > 0; --missing) {
    std::size_t widest = gaps.size();
    double ratio = 0;
    for (std::size_t k = 0; k < gaps.size(); ++k) {
      const double rings_in_gap = gaps[k] / spacing[k];
      const double r = rings_in_gap / (1 + extra[k + 1]);
      if (std::isfinite(r) && std::lround(rings_in_gap) - 1 > extra[k + 1] && r > ratio) {
        ratio = r;
        widest = k;
      }
    }
    if (widest == gaps.size()) break;
    ++extra[widest + 1];
  }
  std::vector<int> row(static_cast<std::size_t>(found));
  int next = std::max(missing, 0);  // what is still missing goes above the top ring
  for (int k = 0; k < found; ++k) {
    next += extra[static_cast<std::size_t>(k)];
    row[static_cast<std::size_t>(k)] = next++;
  }
  return row;
}

/// The sensor's beam count: config.num_beams, else the smallest common count
/// (16, 32, 64, 128) that holds the rings found.
int sensor_beams(int found, const FeatureConfig& config) {
  if (config.num_beams > 0) return std::max(config.num_beams, found);
  for (int beams : {16, 32, 64, 128})
    if (found <= beams) return beams;
  return found;
}

}  // namespace

PointRings point_rings(const LabelledCloud& cloud, const FeatureConfig& config) {
  const auto rings = scan_rings(cloud, config);
  const int found = static_cast<int>(rings.size());
  PointRings out{std::vector<std::int16_t>(cloud.size(), -1), sensor_beams(found, config)};
  const std::vector<int> row = found == out.beams ? std::vector<int>() : ring_rows(ring_elevations(cloud, rings), out.beams);
  for (std::size_t r = 0; r < rings.size(); ++r)
    for (const std::uint32_t i : rings[r]) out.ring[i] = static_cast<std::int16_t>(row.empty() ? static_cast<int>(r) : row[r]);
  return out;
}

Segmenter::Segmenter(SegmenterSpec spec, const fs::path& plugin, FeatureConfig rings)
    : spec_(std::move(spec)), ring_config_(std::move(rings)) {
  const OpenNetwork open = plugin_entry(plugin);
  require_file(spec_.network.weights, fmt::format("network (named by {})", spec_.file.string()));
  spec_.network.logit_offsets = decision_offsets(spec_);
  std::string error;
  runner_.reset(open(spec_.network, error));
  if (!runner_) throw InputError(spec_.network.weights, error + fmt::format(" (described by {})", spec_.file.string()));
}

Segmenter::~Segmenter() = default;

Segmenter::Segmenter(SegmenterSpec spec, std::unique_ptr<NetworkRunner> runner, FeatureConfig rings)
    : spec_(std::move(spec)), ring_config_(std::move(rings)), runner_(std::move(runner)) {}

void Segmenter::check_beams(int beams) const {
  if (spec_.projection.row_mode == RowMode::kRing &&
      std::find(spec_.beams.begin(), spec_.beams.end(), beams) == spec_.beams.end())
    throw InputError(spec_.file, fmt::format("the model is made for {}-beam scans; this scan has {} rings",
                                             beam_list(spec_.beams), beams));
}

std::vector<std::uint16_t> Segmenter::labels(const LabelledCloud& cloud) const { return segment(cloud, false).labels; }

Segmentation Segmenter::segment(const LabelledCloud& cloud, bool confidence) const {
  Segmentation out;
  out.labels.assign(cloud.size(), cls::kUnlabeled);
  if (cloud.empty()) {
    if (confidence) out.confidence.assign(cloud.size(), 0.0f);
    return out;
  }
  PointRings rings;
  if (spec_.projection.row_mode == RowMode::kRing) rings = point_rings(cloud, ring_config_);
  const bool thresholded = spec_.min_confidence > 0.0;
  PointClasses points = point_output(cloud, rings.ring, rings.beams, confidence || thresholded);
  const auto classes = static_cast<int>(spec_.classes.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const bool sure = !thresholded || points.confidence[i] >= spec_.min_confidence;
    if (points.classes[i] > 0 && points.classes[i] < classes && sure)
      out.labels[i] = spec_.classes[static_cast<std::size_t>(points.classes[i])];
  }
  if (confidence) out.confidence = std::move(points.confidence);
  return out;
}

std::vector<std::int16_t> Segmenter::output_classes(const LabelledCloud& cloud, const std::vector<std::int16_t>& rings,
                                                    int beams) const {
  return point_output(cloud, rings, beams, false).classes;
}

namespace {

/// The probability of each point's class at its own pixel (`probabilities`:
/// pixel-major, `classes` per pixel); 0 for points without a pixel or class.
std::vector<float> point_confidence(const RangeImage& image, const std::vector<float>& probabilities, int classes,
                                    const std::vector<std::int16_t>& point_class) {
  std::vector<float> confidence(point_class.size(), 0.0f);
  for (std::size_t i = 0; i < point_class.size(); ++i) {
    const std::int32_t pixel = image.point_pixel[i];
    if (pixel < 0 || point_class[i] <= 0 || point_class[i] >= classes) continue;
    confidence[i] = probabilities[static_cast<std::size_t>(pixel) * static_cast<std::size_t>(classes) +
                                  static_cast<std::size_t>(point_class[i])];
  }
  return confidence;
}

}  // namespace

Segmenter::PointClasses Segmenter::point_output(const LabelledCloud& cloud, const std::vector<std::int16_t>& rings,
                                                int beams, bool confidence) const {
  check_beams(beams);
  const RangeImage image = project_scan(cloud, rings, beams, spec_.projection);
  PixelClasses pixels;
  try {
    pixels = runner_->classify(image.data, image.channels, image.rows, image.cols, confidence);
  } catch (const std::exception& e) {
    throw InputError(spec_.network.weights,
                     fmt::format("the network rejects a {}x{}x{} range image (made for another projection? see {}): {}",
                                 image.channels, image.rows, image.cols, spec_.file.string(), e.what()));
  }
  const auto classes = static_cast<int>(spec_.classes.size());
  PointClasses out;
  out.classes = point_classes(image, pixels.classes, point_ranges(cloud), classes, spec_.knn);
  if (confidence) out.confidence = point_confidence(image, pixels.probabilities, classes, out.classes);
  return out;
}

}  // namespace saloam
