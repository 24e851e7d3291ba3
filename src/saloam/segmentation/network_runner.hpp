#pragma once
// The boundary between saloam and the neural network of the segmentation:
// the network runs in a plugin (libsaloam_segment_torch.so, built with
// libtorch) that saloam loads only when a run segments, so that no other
// command pays libtorch's start-up. Everything that crosses the boundary is
// declared here, in plain types: the plugin depends on nothing else of saloam.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace saloam {

/// The architecture of saloam's own range-image network (segnet in
/// docs/segmentation.md): an encoder-decoder over the range image.
///   stem      conv (in -> w0), stride (1, stem_stride) in columns: the image's
///             columns are thinned to the working resolution at once
///   level 0   residual block (w0)
///   level 1   conv stride 2 (w0 -> w1), residual block
///   level 2   conv stride 2 (w1 -> w2), `context_blocks` residual blocks
///             dilated 1, 2, 4, ... in columns (context along the ring)
///   decoder   bilinear x2, concatenate the level's skip, conv: level 2 -> 1 -> 0
///   head      1x1 conv (w0 -> classes), bilinear x(1, stem_stride) back to
///             the image's columns
/// Every conv is 3x3 with batch norm and leaky ReLU. Rows must be a multiple
/// of 4 and columns of 4 * stem_stride.
struct SegNetShape {
  int in_channels = 6;
  int classes = 20;
  std::array<int, 3> widths{16, 32, 64};
  int stem_stride = 4;
  int context_blocks = 2;
};

enum class NetworkFormat {
  kSegNet,       ///< saloam's SegNet: its parameters in libtorch's archive format (torch::save)
  kTorchScript,  ///< any TorchScript module: forward(Tensor[1, C, H, W]) -> logits [1, K, H, W]
};

struct NetworkSpec {
  NetworkFormat format = NetworkFormat::kSegNet;
  std::string weights;  ///< the file with the network
  SegNetShape shape;    ///< kSegNet: the architecture; kTorchScript: in_channels and classes are checked
  /// Added to each output class's logit before the argmax (empty: nothing;
  /// else one per class): a decision that weighs one kind of error more than
  /// another (SegmenterSpec::dynamic_bias).
  std::vector<float> logit_offsets;
};

/// What a network says about the pixels of a range image.
struct PixelClasses {
  /// Class of each pixel, row-major: the argmax of the logits plus the
  /// spec's offsets over classes 1..K-1 (class 0, unlabeled, is never
  /// predicted).
  std::vector<std::int16_t> classes;
  /// Empty unless asked for: the softmax probability of every class at every
  /// pixel, pixel-major (K numbers per pixel, row-major pixels), of the
  /// logits without the offsets (the offsets are a decision, not evidence).
  std::vector<float> probabilities;
};

/// One loaded network. classify() is called from one thread at a time per
/// runner; a runner computes on the calling thread only (one intra-op
/// thread), so its output does not depend on how many runners work at once.
class NetworkRunner {
 public:
  virtual ~NetworkRunner() = default;
  /// The classes (and with `probabilities` the class probabilities) of every
  /// pixel of a C x rows x cols image (channel-major floats). Throws
  /// std::runtime_error with a short reason (shapes that do not fit, a
  /// network that fails).
  virtual PixelClasses classify(const std::vector<float>& image, int channels, int rows, int cols,
                                bool probabilities = false) = 0;
};

}  // namespace saloam

/// The plugin's entry point: a runner for `spec`, or nullptr with the reason in `error`.
extern "C" saloam::NetworkRunner* saloam_open_network(const saloam::NetworkSpec& spec, std::string& error);
