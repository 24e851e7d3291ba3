#pragma once
// Training data of the segmentation network (`saloam segment-train`):
// labelled scans of the sources of a data recipe (train/data_recipe.hpp),
// kept compactly in memory (9 bytes a point) and cached on disk, and the
// augmented, projected training samples drawn from them. No libtorch here.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/segmentation/range_projection.hpp"
#include "saloam/train/data_recipe.hpp"

namespace saloam {

/// One labelled scan, compact: positions quantised to kScanPositionStep
/// (well below the sensor's noise), remission to 1/255.
struct TrainingScan {
  std::vector<std::array<std::int16_t, 3>> xyz;  ///< sensor frame [kScanPositionStep]
  std::vector<std::uint8_t> remission;           ///< remission * 255
  std::vector<std::uint8_t> target;              ///< SemanticKITTI learning class 0..19 (0 = ignored)
  std::vector<std::uint8_t> ring;                ///< 0 = top beam; 255 = none
  int beams = 0;

  [[nodiscard]] std::size_t size() const { return xyz.size(); }
};

inline constexpr float kScanPositionStep = 0.005f;  ///< [m]: +-163 m in an int16
inline constexpr std::uint8_t kNoRing = 255;

/// A labelled cloud (raw ids, as read or simulated) made compact: targets are
/// learning classes, points farther than 163 m are dropped.
TrainingScan compact_scan(const LabelledCloud& cloud, const std::vector<std::int16_t>& ring, int beams);

struct TrainingScanSet {
  std::string name;
  std::vector<TrainingScan> scans;
  double weight = 1.0;  ///< how often training draws each scan, relative to a weight-1 set's (SourceSpec::weight)
};

/// The scans of one source, every k-th frame: simulated ones rendered in
/// memory with ground-truth labels, folders read with their labels. Rings
/// are recovered as the segmenter recovers them (`rings` settings). With
/// `cache_dir`, kept there as <name>.scans and reused while the source is
/// unchanged. InputError for a source without labels or with noisy labels.
/// Stops early (returning what it has) on stop_requested().
TrainingScanSet build_training_scans(const SourceSpec& spec, const FeatureConfig& rings,
                                 const std::optional<std::filesystem::path>& cache_dir, bool show_progress);

/// Points per learning class over all scans, each set's counted `weight`
/// times (rounded): the class frequencies that training sees, which the loss
/// weights balance.
std::array<std::uint64_t, kNumLearningClasses> class_counts(const std::vector<TrainingScanSet>& sequences);

/// Mean and standard deviation of each channel over the pixels with a point
/// of every `step`-th scan, projected without augmentation; the mask channel
/// keeps mean 0 and deviation 1 (1 where a point is, 0 elsewhere).
void fit_channel_statistics(const std::vector<TrainingScanSet>& sequences, ProjectionSpec& spec, std::size_t step);

/// Augmentations that prepare the network for sensors and scenes it was not
/// trained on. Each draw is a pure function of the sample's seed.
struct ScanAugmentOptions {
  bool rotate = true;                  ///< yaw uniform in [0, 2 pi) (also: where the crop falls)
  double flip = 0.5;                   ///< probability of mirroring y
  double max_tilt_deg = 2.0;           ///< pitch and roll uniform in [-max, max]: other mounts
  double max_height_shift = 0.3;       ///< [m] z shift uniform in [-max, max]: other mounting heights
  double max_range_noise = 0.03;       ///< [m] sigma of range noise uniform in [0, max]
  double max_point_dropout = 0.2;      ///< fraction of points lost, uniform in [0, max]
  double max_ring_dropout = 0.1;       ///< fraction of rings lost, uniform in [0, max]
  double occlusion = 0.5;              ///< probability of 1-3 occluded azimuth sectors of 5-40 deg (from a ring down)
  double remission_constant = 0.2;     ///< probability that remission carries no information (a constant)
  double remission_gamma = 2.0;        ///< remission r -> a r^g + b, g in [1/max, max] (log-uniform)
  double remission_gain = 0.5;         ///< a uniform in [1 - x, 1 + x]
  double remission_offset = 0.1;       ///< b uniform in [-x, x]
  double remission_noise = 0.05;       ///< per-point Gaussian sigma uniform in [0, max]
  /// Probability that a sample is two scans mixed by ring bands (LaserMix:
  /// Kong et al., CVPR 2023): the rings cut into 2-6 bands of equal height,
  /// alternate bands from each scan (both augmented on their own), so that
  /// a few places make many scenes. 0 (the default): no second scan drawn.
  double mix = 0.0;
};

/// Calls v(name, member, description, range) for every augmentation (bool:
/// v(name, member, description)): the one list that training.json, the
/// checkpoint and `segment-train --augment NAME=VALUE` share.
template <class Visitor>
void visit_fields(ScanAugmentOptions& a, Visitor&& v) {
  v("rotate", a.rotate, "yaw uniform in [0, 2 pi)");
  v("flip", a.flip, "probability of mirroring y", Range{0, 1});
  v("max_tilt_deg", a.max_tilt_deg, "[deg] pitch and roll uniform in [-max, max]", Range{0, 30});
  v("max_height_shift", a.max_height_shift, "[m] z shift uniform in [-max, max]", Range{0, 5});
  v("max_range_noise", a.max_range_noise, "[m] sigma of range noise uniform in [0, max]", Range{0, 1});
  v("max_point_dropout", a.max_point_dropout, "fraction of points lost, uniform in [0, max]", Range{0, 0.95});
  v("max_ring_dropout", a.max_ring_dropout, "fraction of rings lost, uniform in [0, max]", Range{0, 0.95});
  v("occlusion", a.occlusion, "probability of occluded azimuth sectors", Range{0, 1});
  v("remission_constant", a.remission_constant, "probability that remission is replaced by a constant", Range{0, 1});
  v("remission_gamma", a.remission_gamma, "remission gamma in [1/max, max] (1: none)", Range{1, 10});
  v("remission_gain", a.remission_gain, "remission gain in [1 - x, 1 + x]", Range{0, 1});
  v("remission_offset", a.remission_offset, "remission offset in [-x, x]", Range{0, 1});
  v("remission_noise", a.remission_noise, "per-point remission noise sigma in [0, max]", Range{0, 1});
  v("mix", a.mix, "probability of mixing in a second scan's ring bands (LaserMix)", Range{0, 1});
}

/// Sets the augmentation `name` from text ("0.1"; "true"/"false" for rotate):
/// the one check of a value from the command line. ConfigError naming the
/// augmentation for an unknown name, unreadable text or a value out of range.
void set_augment_option(ScanAugmentOptions& augment, std::string_view name, std::string_view value);

/// One training sample: the normalised image (C x rows x cols) and the target
/// class of every pixel (the class of the point it shows; 0 = no point or
/// ignored).
struct TrainingSample {
  std::vector<float> image;
  std::vector<std::int64_t> target;
  int rows = 0, cols = 0;
};

/// Augments `scan` (seeded), projects it with `spec` (ring rows) and cuts
/// `crop_columns` consecutive columns (the whole image when 0 or wider).
/// With a `partner` of the same beam count, a share `augment.mix` of the
/// samples (decided by the seed) take alternate ring bands from the partner,
/// augmented with its own draws.
TrainingSample make_training_sample(const TrainingScan& scan, const ProjectionSpec& spec,
                                    const ScanAugmentOptions& augment, std::uint64_t seed, int crop_columns,
                                    const TrainingScan* partner = nullptr);

/// The scan as the segmenter sees it (points, remission; labels left 0) and its rings.
LabelledCloud scan_cloud(const TrainingScan& scan);
std::vector<std::int16_t> training_scan_rings(const TrainingScan& scan);

}  // namespace saloam
