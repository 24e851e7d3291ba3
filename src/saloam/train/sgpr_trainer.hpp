#pragma once
// Training and fine-tuning of SGPR (Kong et al., IROS 2020) with libtorch,
// following the original recipe: pairs of graphs, positive within 3 m and
// negative beyond 20 m, balanced; each pair scored in both orders; binary
// cross-entropy on the sigmoid score; Adam (lr 1e-3, weight decay 5e-4);
// augmentations on the node positions. Beyond the original: half of the
// negatives are hard negatives mined with the current model every epoch
// (for an anchor, among its highest-scoring negatives), and node dropout.
//
// The model is read and written as `.sgw`, the format of the Eigen
// inference, so what is trained is what runs. libtorch stays inside the
// .cpp files (this header does not include it).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "saloam/place/sgpr_weights.hpp"
#include "saloam/train/graph_dataset.hpp"

namespace saloam {

struct SgprOptimizerOptions {
  double learning_rate = 1e-3;  ///< SGPR: Adam, lr 1e-3
  double weight_decay = 5e-4;   ///< SGPR: 5e-4 (Adam's L2 term)
};

/// One network and its Adam optimiser; one call of `step` is one
/// optimisation step on a batch of pairs (each pair scored in both orders).
class SgprTrainer {
 public:
  /// From scratch: parameters drawn from torch's generator seeded with `seed`.
  SgprTrainer(std::uint64_t seed, const SgprOptimizerOptions& options);
  /// From given weights (fine-tuning or resuming); InputError for bad weights.
  SgprTrainer(const SgprWeights& weights, const SgprOptimizerOptions& options);
  ~SgprTrainer();
  SgprTrainer(const SgprTrainer&) = delete;
  SgprTrainer& operator=(const SgprTrainer&) = delete;

  /// One optimisation step (batch norm in train mode); returns the mean
  /// binary cross-entropy of the batch before the step. first, second and
  /// targets (1 = same place, 0 = not) have one entry per pair.
  double step(std::span<const SemanticGraph* const> first, std::span<const SemanticGraph* const> second,
              std::span<const float> targets);
  /// Eval-mode logits of the pairs (running statistics), graph 1 first.
  [[nodiscard]] std::vector<double> logits(std::span<const SemanticGraph* const> first,
                                           std::span<const SemanticGraph* const> second) const;

  /// The current parameters and running statistics as `.sgw` weights.
  [[nodiscard]] SgprWeights weights() const;
  /// Adam's state (moments, step counts), libtorch's archive format.
  void save_optimizer(const std::filesystem::path& file) const;
  void load_optimizer(const std::filesystem::path& file);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct SgprTrainOptions {
  std::filesystem::path out;   ///< output folder (checkpoints, logs, curves, graph cache)
  std::filesystem::path init;  ///< weights to fine-tune; empty = from scratch
  bool resume = false;         ///< continue the run in `out` from its last checkpoint
  int epochs = 20;
  int batch = 16;               ///< pairs per step (SGPR: 16), each scored in both orders
  std::uint64_t seed = 1;
  int threads = 1;
  SgprOptimizerOptions optimizer;
  std::size_t pairs_per_epoch = 4000;  ///< positives + negatives per epoch (half each; fewer positives: all of them)
  double hard_fraction = 0.5;          ///< share of the negatives mined from the current model
  std::size_t hard_pool = 10;          ///< a hard negative is one of the anchor's this many highest-scoring negatives
  PairRecipe pairs;
  PlaceEvalConfig validation;          ///< protocol of the validation max F1 (place-eval's)
  AugmentOptions augment;
  bool show_progress = true;
};

struct EpochRecord {
  int epoch = 0;                 ///< 1-based
  double loss = 0;               ///< mean training loss over the epoch
  std::size_t pairs = 0;         ///< training pairs seen
  double pairs_per_second = 0;   ///< optimisation only
  double seconds = 0;            ///< the whole epoch (mining, training, validation)
  double val_max_f1 = 0;
  double val_recall_at_full_precision = 0;
};

struct SgprTrainResult {
  std::vector<EpochRecord> history;  ///< every epoch of the run, resumed ones included
  double initial_val_max_f1 = 0;     ///< of the initial weights
  int best_epoch = 0;                ///< 0: the initial weights were never beaten
  bool interrupted = false;
};

/// Runs the training (see the header comment) and writes into options.out:
///   model.sgw             the weights after the last completed epoch
///   best.sgw              the weights with the best validation max F1
///   checkpoint/           optimizer.pt + state.json: what --resume needs
///   training.json         options, data, per-epoch records
///   curves.png            training loss and validation max F1 per epoch
/// Deterministic for a seed and thread count: every epoch draws its pairs and
/// augmentations from a generator seeded with (seed, epoch), so a resumed run
/// repeats exactly what an uninterrupted one does. On stop_requested() the
/// current epoch is abandoned at the next batch and the last checkpoint kept.
/// `on_epoch` is called after every epoch (progress display).
SgprTrainResult train_sgpr(std::span<const GraphSequence> train, std::span<const GraphSequence> validation,
                           const SgprTrainOptions& options, const nlohmann::json& run_info = {},
                           const std::function<void(const EpochRecord&)>& on_epoch = {});

}  // namespace saloam
