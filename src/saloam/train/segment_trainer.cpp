#include "saloam/train/segment_trainer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <future>
#include <map>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/eval/segmentation_score.hpp"
#include "saloam/segmentation/segmenter.hpp"
#include "saloam/segmentation/torch/segnet.hpp"
#include "saloam/train/training_run.hpp"
#include "saloam/viz/canvas.hpp"

namespace saloam {

namespace fs = std::filesystem;

// ---------------------------------------------------------------- losses

namespace {

/// Gradient of the Lovasz extension of the Jaccard loss with respect to the
/// sorted errors (Berman et al., Alg. 1), from the sorted foreground flags.
torch::Tensor lovasz_gradient(const torch::Tensor& foreground_sorted) {
  const auto total = foreground_sorted.sum();
  const auto intersection = total - foreground_sorted.cumsum(0);
  const auto union_ = total + (1 - foreground_sorted).cumsum(0);
  auto jaccard = 1 - intersection / union_;
  if (jaccard.size(0) > 1) jaccard = torch::cat({jaccard.slice(0, 0, 1), jaccard.slice(0, 1) - jaccard.slice(0, 0, -1)});
  return jaccard;
}

/// Class-weighted cross-entropy of pixel logits [N, H, W, K] against targets
/// [N, H, W], class 0 ignored: PyTorch's cross_entropy(weight, ignore_index
/// 0), over the class axis that lies last in memory here.
torch::Tensor weighted_cross_entropy(const torch::Tensor& logits, const torch::Tensor& target,
                                     const torch::Tensor& class_weights) {
  const auto log_p = torch::log_softmax(logits, -1);
  const auto picked = log_p.gather(-1, target.unsqueeze(-1)).squeeze(-1);
  const auto weight = class_weights.index({target}) * (target > 0).to(torch::kFloat32);
  return -(picked * weight).sum() / weight.sum().clamp_min(1e-12);
}

/// Lovasz-softmax loss over the pixels with a class (target > 0), averaged
/// over the classes present in the batch. Logits [N, H, W, K], targets [N, H, W].
torch::Tensor lovasz_softmax(const torch::Tensor& logits, const torch::Tensor& target) {
  const int64_t classes = logits.size(-1);
  const auto labels = target.reshape({-1});
  const auto valid = labels > 0;
  const auto probabilities = torch::softmax(logits, -1).reshape({-1, classes}).index({valid});
  const auto kept = labels.index({valid});
  std::vector<torch::Tensor> losses;
  for (int64_t c = 1; c < classes; ++c) {
    const auto foreground = (kept == c).to(torch::kFloat32);
    if (foreground.sum().item<float>() == 0) continue;
    const auto errors = (foreground - probabilities.select(1, c)).abs();
    const auto [sorted, order] = torch::sort(errors, 0, /*descending=*/true);
    losses.push_back(torch::dot(sorted, lovasz_gradient(foreground.index({order}))));
  }
  if (losses.empty()) return logits.sum() * 0;
  return torch::stack(losses).mean();
}

/// The trainer's network in eval mode, for the inference path.
class TrainerRunner final : public NetworkRunner {
 public:
  explicit TrainerRunner(SegNet net) : net_(std::move(net)) {}
  PixelClasses classify(const std::vector<float>& image, int channels, int rows, int cols, bool probabilities) override {
    torch::NoGradGuard no_grad;
    net_->eval();
    return pixel_classes(net_->pixel_logits(image_tensor(image, channels, rows, cols)), {}, probabilities);
  }

 private:
  SegNet net_;
};

}  // namespace

// ---------------------------------------------------------------- trainer

struct SegmentTrainer::Impl {
  SegNet net;
  std::unique_ptr<torch::optim::Adam> adam;
  torch::Tensor class_weights;
  double lovasz_weight;

  Impl(const SegNetShape& shape, const SegmentTrainOptions& options)
      : net(shape), class_weights(torch::ones({shape.classes})), lovasz_weight(options.lovasz_weight) {
    adam = std::make_unique<torch::optim::Adam>(
        net->parameters(), torch::optim::AdamOptions(options.learning_rate).weight_decay(options.weight_decay));
  }
};

SegmentTrainer::SegmentTrainer(const SegNetShape& shape, std::uint64_t seed, const SegmentTrainOptions& options) {
  keep_freed_memory_for_reuse();
  torch::manual_seed(seed);
  impl_ = std::make_unique<Impl>(shape, options);
}

SegmentTrainer::~SegmentTrainer() = default;

void SegmentTrainer::set_class_weights(const std::array<double, kNumLearningClasses>& weights) {
  auto w = torch::zeros({impl_->net->shape().classes});
  for (int64_t c = 0; c < w.size(0) && c < kNumLearningClasses; ++c) w[c] = weights[static_cast<std::size_t>(c)];
  impl_->class_weights = w;
}

double SegmentTrainer::step(std::span<const TrainingSample> batch, double learning_rate) {
  const int64_t n = static_cast<int64_t>(batch.size()), rows = batch.front().rows, cols = batch.front().cols;
  const int64_t channels = static_cast<int64_t>(batch.front().image.size()) / (rows * cols);
  auto images = torch::empty({n, channels, rows, cols});
  auto targets = torch::empty({n, rows, cols}, torch::kInt64);
  for (int64_t b = 0; b < n; ++b) {
    const auto& s = batch[static_cast<std::size_t>(b)];
    if (s.rows != rows || s.cols != cols) throw std::invalid_argument("SegmentTrainer::step: samples of one size expected");
    std::memcpy(images[b].data_ptr<float>(), s.image.data(), s.image.size() * sizeof(float));
    std::memcpy(targets[b].data_ptr<int64_t>(), s.target.data(), s.target.size() * sizeof(int64_t));
  }
  auto& net = impl_->net;
  net->train();
  const auto logits = net->pixel_logits(images.contiguous(torch::MemoryFormat::ChannelsLast));
  auto loss = weighted_cross_entropy(logits, targets, impl_->class_weights);
  if (impl_->lovasz_weight > 0) loss = loss + impl_->lovasz_weight * lovasz_softmax(logits, targets);
  for (auto& group : impl_->adam->param_groups())
    static_cast<torch::optim::AdamOptions&>(group.options()).lr(learning_rate);
  impl_->adam->zero_grad();
  loss.backward();
  impl_->adam->step();
  return loss.item<double>();
}

std::unique_ptr<NetworkRunner> SegmentTrainer::runner() { return std::make_unique<TrainerRunner>(impl_->net); }

void SegmentTrainer::save_model(const fs::path& file) const { torch::save(impl_->net, file.string()); }

void SegmentTrainer::load_model(const fs::path& file) {
  try {
    load_segnet(impl_->net, file.string());
  } catch (const c10::Error& e) {
    throw InputError(file, std::string("cannot read the network: ") + e.what_without_backtrace());
  } catch (const std::runtime_error& e) {
    throw InputError(file, e.what());
  }
}

void SegmentTrainer::save_optimizer(const fs::path& file) const { torch::save(*impl_->adam, file.string()); }

void SegmentTrainer::load_optimizer(const fs::path& file) {
  try {
    torch::load(*impl_->adam, file.string());
  } catch (const c10::Error& e) {
    throw InputError(file, std::string("cannot read the optimizer state: ") + e.what_without_backtrace());
  }
}

void set_class_weight_factor(std::array<double, kNumLearningClasses>& factors, std::string_view name, double factor) {
  const auto c = learning_class_id(name);
  if (!c || !(factor > 0 && factor <= 100))
    throw ConfigError(fmt::format("class weight '{}={}': expected a learning class (e.g. pole) and a factor in (0, 100]",
                                  name, factor));
  factors[*c] = factor;
}

std::array<double, kNumLearningClasses> class_weights_from_counts(const std::array<std::uint64_t, kNumLearningClasses>& counts,
                                                                 const std::array<double, kNumLearningClasses>& factors) {
  std::array<double, kNumLearningClasses> weights{};
  double total = 0, sum = 0;
  int present = 0;
  for (int c = 1; c < kNumLearningClasses; ++c) total += static_cast<double>(counts[c]);
  if (total <= 0) return weights;
  for (int c = 1; c < kNumLearningClasses; ++c)
    if (counts[c] > 0) {
      weights[c] = factors[c] / std::sqrt(static_cast<double>(counts[c]) / total);
      sum += weights[c];
      ++present;
    }
  for (auto& w : weights) w *= present / sum;
  return weights;
}

}  // namespace saloam
