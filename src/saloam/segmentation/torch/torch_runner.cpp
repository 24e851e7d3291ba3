// The network plugin (libsaloam_segment_torch.so): runs SegNet models and
// TorchScript models with libtorch on the CPU, one intra-op thread per
// calling thread. saloam loads it with dlopen only when a run segments.

#include <malloc.h>
#include <torch/script.h>
#include <torch/torch.h>

#include <memory>
#include <sstream>
#include <string>

#include "saloam/segmentation/network_runner.hpp"
#include "saloam/segmentation/torch/segnet.hpp"

namespace saloam {
namespace {

/// The first line of a libtorch error (its messages carry C++ back traces).
std::string first_line(const std::string& text) {
  const auto end = text.find('\n');
  return text.substr(0, std::min<std::size_t>(end, 300));
}

/// Every thread that runs a network computes alone: libtorch's intra-op
/// threads are per calling thread (OpenMP), so the output does not depend on
/// how many threads run networks side by side.
void use_one_thread() {
  thread_local bool done = false;
  if (!done) {
    at::set_num_threads(1);
    done = true;
  }
}

/// libtorch allocates and frees its activations and logits (megabytes) for
/// every scan. By default glibc's malloc hands a thread arena's free top back
/// to the kernel and maps large blocks afresh, so each scan would fault its
/// buffers in again, which costs more than the network itself
/// (docs/segmentation.md, "Speed and memory"). Keeping 64 MiB of free top per
/// arena (a thread arena's heap is at most 64 MiB) lets the next scan reuse
/// the same pages. Process-wide, set once, when the first network opens.
void keep_freed_memory_for_reuse() {
#ifdef __GLIBC__
  static const bool done = mallopt(M_TOP_PAD, 64 << 20) == 1;
  (void)done;
#endif
}

void check_output(const torch::Tensor& logits, int classes, int rows, int cols) {
  if (logits.dim() != 4 || logits.size(0) != 1 || logits.size(1) != classes || logits.size(2) != rows ||
      logits.size(3) != cols) {
    std::ostringstream shape;
    shape << logits.sizes();
    throw std::runtime_error("the network outputs " + shape.str() + ", not [1, " + std::to_string(classes) + ", " +
                             std::to_string(rows) + ", " + std::to_string(cols) + "] (one logit per class listed)");
  }
}

class SegNetRunner final : public NetworkRunner {
 public:
  explicit SegNetRunner(const NetworkSpec& spec) : net_(spec.shape), offsets_(offsets_tensor(spec.logit_offsets)) {
    load_segnet(net_, spec.weights);
    net_->eval();
    net_->fold_batch_norm();
  }

  PixelClasses classify(const std::vector<float>& image, int channels, int rows, int cols, bool probabilities) override {
    use_one_thread();
    const auto& shape = net_->shape();
    if (channels != shape.in_channels)
      throw std::runtime_error("the network takes " + std::to_string(shape.in_channels) + " channels, not " +
                               std::to_string(channels));
    if (const auto problem = segnet_size_problem(shape, rows, cols); !problem.empty()) throw std::runtime_error(problem);
    torch::NoGradGuard no_grad;
    return pixel_classes(net_->pixel_logits(image_tensor(image, channels, rows, cols)), offsets_, probabilities);
  }

 private:
  SegNet net_;
  torch::Tensor offsets_;  ///< undefined: no decision bias
};

class TorchScriptRunner final : public NetworkRunner {
 public:
  explicit TorchScriptRunner(const NetworkSpec& spec)
      : module_(torch::jit::load(spec.weights)), classes_(spec.shape.classes), offsets_(offsets_tensor(spec.logit_offsets)) {
    module_.eval();
  }

  PixelClasses classify(const std::vector<float>& image, int channels, int rows, int cols, bool probabilities) override {
    use_one_thread();
    torch::NoGradGuard no_grad;
    torch::jit::IValue out = module_.forward({image_tensor(image, channels, rows, cols).contiguous()});
    if (out.isTuple()) out = out.toTuple()->elements().at(0);
    if (!out.isTensor()) throw std::runtime_error("the network's forward() returns no tensor");
    const torch::Tensor logits = out.toTensor().to(torch::kFloat32);
    check_output(logits, classes_, rows, cols);
    return pixel_classes(logits.permute({0, 2, 3, 1}), offsets_, probabilities);
  }

 private:
  torch::jit::Module module_;
  int classes_;
  torch::Tensor offsets_;  ///< undefined: no decision bias
};

std::unique_ptr<NetworkRunner> open(const NetworkSpec& spec) {
  keep_freed_memory_for_reuse();
  if (spec.format == NetworkFormat::kTorchScript) return std::make_unique<TorchScriptRunner>(spec);
  return std::make_unique<SegNetRunner>(spec);
}

}  // namespace
}  // namespace saloam

extern "C" __attribute__((visibility("default"))) saloam::NetworkRunner* saloam_open_network(
    const saloam::NetworkSpec& spec, std::string& error) {
  try {
    return saloam::open(spec).release();
  } catch (const c10::Error& e) {
    error = "not a usable " +
            std::string(spec.format == saloam::NetworkFormat::kSegNet ? "SegNet weights file (saloam's libtorch archive)"
                                                                      : "TorchScript model") +
            ": " + saloam::first_line(e.what_without_backtrace());
  } catch (const std::exception& e) {
    error = (spec.format == saloam::NetworkFormat::kSegNet ? "not a usable SegNet weights file: " : "") +
            std::string(e.what());
  }
  return nullptr;
}
