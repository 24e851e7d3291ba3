#include "saloam/segmentation/torch/segnet.hpp"

#include <map>
#include <string>

namespace saloam {
namespace {

namespace F = torch::nn::functional;

constexpr double kLeakySlope = 0.1;

torch::Tensor resized(const torch::Tensor& x, int64_t rows, int64_t cols) {
  return F::interpolate(x, F::InterpolateFuncOptions()
                               .size(std::vector<int64_t>{rows, cols})
                               .mode(torch::kBilinear)
                               .align_corners(false));
}

}  // namespace

ConvBnImpl::ConvBnImpl(const ConvSpec& spec) : stride_(spec.stride), dilation_(spec.dilation) {
  const auto& [kernel, stride, dilation] = std::tie(spec.kernel, spec.stride, spec.dilation);
  padding_ = {dilation[0] * (kernel[0] - 1) / 2, dilation[1] * (kernel[1] - 1) / 2};
  conv_ = register_module("conv", torch::nn::Conv2d(torch::nn::Conv2dOptions(spec.in, spec.out, {kernel[0], kernel[1]})
                                                        .stride({stride[0], stride[1]})
                                                        .padding({padding_[0], padding_[1]})
                                                        .dilation({dilation[0], dilation[1]})
                                                        .bias(false)));
  bn_ = register_module("bn", torch::nn::BatchNorm2d(spec.out));
}

torch::Tensor ConvBnImpl::forward(const torch::Tensor& x, bool activate) {
  torch::Tensor y;
  if (folded_weight_.defined()) {
    y = torch::conv2d(x, folded_weight_, folded_bias_, stride_, padding_, dilation_);
  } else {
    y = bn_(conv_(x));
  }
  return activate ? F::leaky_relu(y, F::LeakyReLUFuncOptions().negative_slope(kLeakySlope).inplace(true)) : y;
}

void ConvBnImpl::fold_batch_norm() {
  torch::NoGradGuard no_grad;
  const auto scale = bn_->weight / torch::sqrt(bn_->running_var + bn_->options.eps());
  folded_weight_ = (conv_->weight * scale.view({-1, 1, 1, 1})).contiguous(torch::MemoryFormat::ChannelsLast);
  folded_bias_ = bn_->bias - bn_->running_mean * scale;
}

ResidualBlockImpl::ResidualBlockImpl(int channels, int64_t column_dilation) {
  first_ = register_module("first", ConvBn(ConvSpec{channels, channels, {3, 3}, {1, 1}, {1, column_dilation}}));
  second_ = register_module("second", ConvBn(ConvSpec{channels, channels, {3, 3}, {1, 1}, {1, 1}}));
}

torch::Tensor ResidualBlockImpl::forward(const torch::Tensor& x) {
  auto y = second_->forward(first_->forward(x), /*activate=*/false);
  return F::leaky_relu(y + x, F::LeakyReLUFuncOptions().negative_slope(kLeakySlope).inplace(true));
}

void ResidualBlockImpl::fold_batch_norm() {
  first_->fold_batch_norm();
  second_->fold_batch_norm();
}

SegNetImpl::SegNetImpl(const SegNetShape& shape) : shape_(shape) {
  const auto [w0, w1, w2] = shape.widths;
  const int64_t s = shape.stem_stride;
  const int64_t stem_width = std::max<int64_t>(3, 2 * s - 1);  // every column reaches an output
  stem_ = register_module("stem", ConvBn(ConvSpec{shape.in_channels, w0, {3, stem_width}, {1, s}, {1, 1}}));
  level0_ = register_module("level0", ResidualBlock(w0, 1));
  down1_ = register_module("down1", ConvBn(ConvSpec{w0, w1, {3, 3}, {2, 2}, {1, 1}}));
  level1_ = register_module("level1", ResidualBlock(w1, 1));
  down2_ = register_module("down2", ConvBn(ConvSpec{w1, w2, {3, 3}, {2, 2}, {1, 1}}));
  context_ = register_module("context", torch::nn::ModuleList());
  for (int i = 0; i < shape.context_blocks; ++i) context_->push_back(ResidualBlock(w2, int64_t{1} << std::min(i, 3)));
  up2_ = register_module("up2", ConvBn(ConvSpec{w2 + w1, w1, {3, 3}, {1, 1}, {1, 1}}));
  up1_ = register_module("up1", ConvBn(ConvSpec{w1 + w0, w0, {3, 3}, {1, 1}, {1, 1}}));
  // One logit per class and column phase: the stem's stride is undone by
  // giving every working-resolution column s columns of output.
  head_ = register_module("head", torch::nn::Conv2d(torch::nn::Conv2dOptions(w0, shape.classes * s, 1)));
}

torch::Tensor SegNetImpl::pixel_logits(const torch::Tensor& x) {
  const auto l0 = level0_->forward(stem_->forward(x));
  const auto l1 = level1_->forward(down1_->forward(l0));
  auto l2 = down2_->forward(l1);
  for (const auto& block : *context_) l2 = block->as<ResidualBlock>()->forward(l2);
  const auto u1 = up2_->forward(torch::cat({resized(l2, l1.size(2), l1.size(3)), l1}, 1));
  const auto u0 = up1_->forward(torch::cat({resized(u1, l0.size(2), l0.size(3)), l0}, 1));
  // libtorch 1.13 runs a 1x1 convolution of a small batch on one thread
  // with its slow reference kernel (five times oneDNN's time here, forward
  // and backward); a dilation, which changes nothing for a 1x1 kernel, sends
  // it to oneDNN.
  const auto logits = torch::conv2d(u0, head_->weight, head_->bias, /*stride=*/at::IntArrayRef{1, 1},
                                    /*padding=*/at::IntArrayRef{0, 0}, /*dilation=*/at::IntArrayRef{2, 2});
  // Channel j * K + k is class k at column phase j: channels-last, the
  // output is [N, H, W/s, s, K] in memory, which is [N, H, W, K] (no copy).
  const int64_t n = logits.size(0), h = logits.size(2), w = logits.size(3);
  return logits.permute({0, 2, 3, 1}).reshape({n, h, w * shape_.stem_stride, shape_.classes});
}

torch::Tensor SegNetImpl::forward(const torch::Tensor& x) { return pixel_logits(x).permute({0, 3, 1, 2}); }

void SegNetImpl::fold_batch_norm() {
  for (auto* block : {&stem_, &down1_, &down2_, &up2_, &up1_}) (*block)->fold_batch_norm();
  level0_->fold_batch_norm();
  level1_->fold_batch_norm();
  for (const auto& block : *context_) block->as<ResidualBlock>()->fold_batch_norm();
}

namespace {

std::map<std::string, std::vector<int64_t>> tensor_shapes(const SegNet& net) {
  std::map<std::string, std::vector<int64_t>> shapes;
  for (const auto& item : net->named_parameters()) shapes[item.key()] = item.value().sizes().vec();
  for (const auto& item : net->named_buffers()) shapes[item.key()] = item.value().sizes().vec();
  return shapes;
}

std::string shape_text(const std::vector<int64_t>& shape) {
  std::string text = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) text += (i ? ", " : "") + std::to_string(shape[i]);
  return text + "]";
}

}  // namespace

void load_segnet(SegNet& net, const std::string& file) {
  const auto expected = tensor_shapes(net);
  torch::serialize::InputArchive archive;
  archive.load_from(file);
  net->load(archive);
  const auto loaded = tensor_shapes(net);
  for (const auto& [name, shape] : expected)
    if (loaded.at(name) != shape)
      throw std::runtime_error("weights of another architecture: " + name + " is " + shape_text(loaded.at(name)) +
                               " where the description's network has " + shape_text(shape));
}

torch::Tensor image_tensor(const std::vector<float>& image, int channels, int rows, int cols) {
  if (image.size() != static_cast<std::size_t>(channels) * static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols))
    throw std::runtime_error("image size does not match its shape");
  return torch::from_blob(const_cast<float*>(image.data()), {1, channels, rows, cols}, torch::kFloat32)
      .contiguous(torch::MemoryFormat::ChannelsLast);
}

torch::Tensor offsets_tensor(const std::vector<float>& offsets) {
  return offsets.empty() ? torch::Tensor() : torch::tensor(offsets, torch::kFloat32);
}

PixelClasses pixel_classes(torch::Tensor pixel_logits, const torch::Tensor& offsets, bool probabilities) {
  torch::Tensor logits = pixel_logits.squeeze(0);
  PixelClasses out;
  if (probabilities) {
    const auto p = torch::softmax(logits, 2).contiguous();
    out.probabilities.assign(p.data_ptr<float>(), p.data_ptr<float>() + p.numel());
  }
  if (offsets.defined()) {
    if (offsets.numel() != logits.size(2))
      throw std::runtime_error("logit offsets for " + std::to_string(offsets.numel()) + " classes, the network has " +
                               std::to_string(logits.size(2)));
    logits.add_(offsets);
  }
  const auto best = (logits.slice(2, 1).argmax(2) + 1).to(torch::kInt16).contiguous();
  out.classes.assign(best.data_ptr<std::int16_t>(), best.data_ptr<std::int16_t>() + best.numel());
  return out;
}

std::string segnet_size_problem(const SegNetShape& shape, int64_t rows, int64_t cols) {
  if (rows % 4 != 0) return "rows (" + std::to_string(rows) + ") must be a multiple of 4";
  const int64_t step = 4 * shape.stem_stride;
  if (cols % step != 0) return "columns (" + std::to_string(cols) + ") must be a multiple of " + std::to_string(step);
  return {};
}

}  // namespace saloam
