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
#include "saloam/scan/rings.hpp"

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
