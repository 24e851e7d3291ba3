#pragma once
// Training of SegNet, saloam's range-image segmentation network
// (segmentation/network_runner.hpp), with libtorch on the CPU, from labelled
// scans (scan_dataset.hpp). The recipe (docs/segmentation.md):
//   - a sample is a scan drawn uniformly, augmented (ScanAugmentOptions),
//     projected with ring rows and `columns` columns, and cut to about
//     `pixels_per_sample` pixels (64 x 512, 32 x 1024, 16 x 2048 with the
//     defaults); a batch holds scans of one beam count;
//   - the loss is the class-weighted cross-entropy (weights 1 / sqrt of the
//     class frequency times a factor per class, 1 unless given; mean 1)
//     plus the Lovasz-softmax loss (Berman et al., CVPR 2018), as SalsaNext
//     trains; class 0 (unlabeled) is ignored;
//   - Adam, the learning rate rising linearly over the first epoch and
//     falling along a cosine to 1 % at the last;
//   - every epoch, the mean IoU of whole validation scans through the
//     inference path (projection, network, k-nearest-neighbour vote).
// Deterministic for a seed and thread count; a resumed run repeats exactly
// what an uninterrupted one does. libtorch stays in the .cpp files.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "saloam/segmentation/segmenter_spec.hpp"
#include "saloam/train/scan_dataset.hpp"

namespace saloam {

/// 1 for every learning class.
constexpr std::array<double, kNumLearningClasses> uniform_class_factors() {
  std::array<double, kNumLearningClasses> f{};
  f.fill(1.0);
  return f;
}

/// Sets the loss-weight factor of the learning class `name`: the one check of
/// a factor whether it comes from the command line or a resumed run's state.
/// ConfigError for an unknown class or a factor outside (0, 100].
void set_class_weight_factor(std::array<double, kNumLearningClasses>& factors, std::string_view name, double factor);

struct SegmentTrainOptions {
  std::filesystem::path out;   ///< output folder: models, checkpoint/, training.json, curves.png, scans/ (cache)
  bool resume = false;         ///< continue the run in `out` from its last checkpoint
  std::filesystem::path init;  ///< a SegNet description (.yaml) to fine-tune; empty = from scratch
  int epochs = 30;
  std::size_t samples_per_epoch = 2000;
  int batch = 8;                       ///< samples per step
  int pixels_per_sample = 64 * 512;    ///< a sample is cut to rows x (this / rows) pixels
  int columns = 2048;                  ///< image columns of the projection
  double learning_rate = 2e-3;
  double weight_decay = 1e-4;          ///< Adam's L2 term
  double lovasz_weight = 0.0;          ///< weight of the Lovasz-softmax term (0: off; it costs 3x the step)
  /// Factors on the loss weights of chosen learning classes (others 1), e.g.
  /// to favour the recall of thin classes; index 0 unused.
  std::array<double, kNumLearningClasses> class_weight_factors = uniform_class_factors();
  std::uint64_t seed = 1;
  int threads = 1;
  SegNetShape shape;                   ///< in_channels and classes are set by the trainer
  ScanAugmentOptions augment;
  std::size_t validation_scans = 200;  ///< at most this many validation scans (evenly spread) per epoch
  bool show_progress = true;
};

struct SegmentEpochRecord {
  int epoch = 0;                   ///< 1-based
  double loss = 0;                 ///< mean training loss over the epoch
  double learning_rate = 0;        ///< at the end of the epoch
  std::size_t samples = 0;
  double samples_per_second = 0;   ///< optimisation only
  double seconds = 0;              ///< the whole epoch (training and validation)
  double val_miou = 0;             ///< mean IoU over the classes in the validation truth
  double val_big_miou = 0;         ///< mean IoU over the eight big classes (kBigClasses)
  std::array<double, kNumLearningClasses> val_iou{};  ///< per learning class (NaN: absent)
};

struct SegmentTrainResult {
  std::vector<SegmentEpochRecord> history;
  int best_epoch = 0;
  bool interrupted = false;
};

/// SemanticKITTI's eight most frequent classes (road, sidewalk, building,
/// vegetation, terrain, fence, car, parking), as learning classes.
inline constexpr std::array<int, 8> kBigClasses{9, 11, 13, 15, 17, 14, 1, 10};

/// Runs the training and writes into options.out:
///   model.pt, model.yaml   the network after the last completed epoch and its description
///   best.pt, best.yaml     the network with the best validation mean IoU
///   checkpoint/            what --resume needs
///   training.json          options, data, per-epoch records (per-class IoU)
///   curves.png             training loss and validation mean IoU per epoch
/// On stop_requested() the current epoch is abandoned and the last checkpoint kept.
SegmentTrainResult train_segmenter(const std::vector<TrainingScanSet>& train, const std::vector<TrainingScanSet>& validation,
                                   const SegmentTrainOptions& options, const nlohmann::json& run_info = {},
                                   const std::function<void(const SegmentEpochRecord&)>& on_epoch = {});

/// The options of the run in `out` (its checkpoint's), with `epochs`,
/// `show_progress` and `out` from `given`: what --resume continues with.
/// InputError when `out` holds no checkpoint.
SegmentTrainOptions resumed_options(const std::filesystem::path& out, const SegmentTrainOptions& given);

/// One network and its optimiser (exposed for tests).
class SegmentTrainer {
 public:
  SegmentTrainer(const SegNetShape& shape, std::uint64_t seed, const SegmentTrainOptions& options);
  ~SegmentTrainer();
  SegmentTrainer(const SegmentTrainer&) = delete;
  SegmentTrainer& operator=(const SegmentTrainer&) = delete;

  /// One optimisation step on samples of one size; returns the batch's loss before the step.
  double step(std::span<const TrainingSample> batch, double learning_rate);
  /// Loss weights per learning class (index 0 unused).
  void set_class_weights(const std::array<double, kNumLearningClasses>& weights);
  /// An in-process view of the network in eval mode for the inference path.
  [[nodiscard]] std::unique_ptr<NetworkRunner> runner();
  void save_model(const std::filesystem::path& file) const;
  void load_model(const std::filesystem::path& file);
  void save_optimizer(const std::filesystem::path& file) const;
  void load_optimizer(const std::filesystem::path& file);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Loss weights from class point counts: 1 / sqrt(frequency) times the
/// class's factor for classes present (mean 1 over them), 0 for absent ones
/// and class 0.
std::array<double, kNumLearningClasses> class_weights_from_counts(
    const std::array<std::uint64_t, kNumLearningClasses>& counts,
    const std::array<double, kNumLearningClasses>& factors = uniform_class_factors());

}  // namespace saloam
