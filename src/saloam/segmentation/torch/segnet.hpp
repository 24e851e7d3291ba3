#pragma once
// SegNet, saloam's range-image segmentation network, as a libtorch module:
// the architecture described by SegNetShape (../network_runner.hpp). The
// trainer (train/) and the network plugin (torch_runner.cpp) share it, so
// what is trained is what runs. Includes libtorch: only code built with
// libtorch includes this header.

#include <torch/torch.h>

#include "saloam/segmentation/network_runner.hpp"

namespace saloam {

/// Shape of one convolution.
struct ConvSpec {
  int in = 0, out = 0;
  std::array<int64_t, 2> kernel{3, 3}, stride{1, 1}, dilation{1, 1};
};

/// 2D convolution, batch norm and leaky ReLU. For inference the batch norm
/// can be folded into the convolution (fold_batch_norm): same function, one
/// pass over the data instead of three.
class ConvBnImpl : public torch::nn::Module {
 public:
  explicit ConvBnImpl(const ConvSpec& spec);
  torch::Tensor forward(const torch::Tensor& x, bool activate = true);
  /// Eval-mode batch norm folded into a weight and bias used from now on.
  void fold_batch_norm();

 private:
  torch::nn::Conv2d conv_{nullptr};
  torch::nn::BatchNorm2d bn_{nullptr};
  std::array<int64_t, 2> stride_, dilation_, padding_{};
  torch::Tensor folded_weight_, folded_bias_;
};
TORCH_MODULE(ConvBn);

/// Two 3x3 ConvBn with a skip connection; the first dilated in columns.
class ResidualBlockImpl : public torch::nn::Module {
 public:
  ResidualBlockImpl(int channels, int64_t column_dilation);
  torch::Tensor forward(const torch::Tensor& x);
  void fold_batch_norm();

 private:
  ConvBn first_{nullptr}, second_{nullptr};
};
TORCH_MODULE(ResidualBlock);

class SegNetImpl : public torch::nn::Module {
 public:
  explicit SegNetImpl(const SegNetShape& shape);
  /// Logits [N, classes, H, W] of images [N, in_channels, H, W] (a view of
  /// pixel_logits()); H a multiple of 4, W of 4 * stem_stride.
  torch::Tensor forward(const torch::Tensor& x);
  /// The same logits pixel by pixel, [N, H, W, classes], contiguous for
  /// channels-last images: what the head computes, what the loss and the
  /// argmax read.
  torch::Tensor pixel_logits(const torch::Tensor& x);
  /// For inference in eval mode: folds every batch norm into its convolution.
  void fold_batch_norm();
  [[nodiscard]] const SegNetShape& shape() const { return shape_; }

 private:
  SegNetShape shape_;
  ConvBn stem_{nullptr}, down1_{nullptr}, down2_{nullptr}, up2_{nullptr}, up1_{nullptr};
  ResidualBlock level0_{nullptr}, level1_{nullptr};
  torch::nn::ModuleList context_{nullptr};
  torch::nn::Conv2d head_{nullptr};
};
TORCH_MODULE(SegNet);

/// Reads weights saved with torch::save(net) into `net`, checking that they
/// hold exactly its parameters and buffers with their shapes (libtorch's own
/// loader accepts other shapes silently). std::runtime_error naming the first
/// difference; c10::Error for a file that is not a libtorch archive.
void load_segnet(SegNet& net, const std::string& file);

/// A C x rows x cols image (channel-major floats) as a [1, C, rows, cols]
/// tensor in channels-last layout (the fast one for CPU convolutions).
torch::Tensor image_tensor(const std::vector<float>& image, int channels, int rows, int cols);
/// The logit offsets of a model description (NetworkSpec::logit_offsets) as
/// a tensor that pixel_classes adds; undefined when there are none.
torch::Tensor offsets_tensor(const std::vector<float>& offsets);
/// What logits [1, H, W, K] say of every pixel (row-major): the class, the
/// argmax of the logits plus `offsets` (undefined, or one per class) over
/// classes 1..K-1 (class 0, unlabeled, is never predicted), and with
/// `probabilities` the softmax of the logits without the offsets. The
/// offsets are added in place: the logits are a network's output, used once.
PixelClasses pixel_classes(torch::Tensor pixel_logits, const torch::Tensor& offsets = {},
                           bool probabilities = false);

/// "rows must be a multiple of 4 ..." when an image of rows x cols does not
/// fit `shape`; empty when it does.
std::string segnet_size_problem(const SegNetShape& shape, int64_t rows, int64_t cols);

}  // namespace saloam
