// SGPR weights in the .sgw format (parse_sgpr_weights), then the network
// built from them (SgprNetwork checks every tensor's shape).

#include <cmath>

#include "fuzz_support.hpp"
#include "saloam/place/sgpr_network.hpp"
#include "saloam/place/sgpr_weights.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  const std::filesystem::path file = "model.sgw";
  try {
    const SgprWeights weights = parse_sgpr_weights(fuzz::as_bytes(data, size), file);
    SALOAM_FUZZ_CHECK(!weights.tensors.empty());
    std::size_t bytes = 12;  // magic and count
    for (const auto& [name, tensor] : weights.tensors) {
      SALOAM_FUZZ_CHECK(!name.empty());
      SALOAM_FUZZ_CHECK(!tensor.dims.empty() && tensor.dims.size() <= 4);
      std::size_t elements = 1;
      for (const auto d : tensor.dims) elements *= d;
      SALOAM_FUZZ_CHECK(elements == tensor.values.size());
      for (const float v : tensor.values) SALOAM_FUZZ_CHECK(std::isfinite(v));
      bytes += 8 + name.size() + 4 * tensor.dims.size() + 4 * elements;
    }
    SALOAM_FUZZ_CHECK(bytes == size);
    SALOAM_FUZZ_CHECK(serialize_sgpr_weights(weights).size() == size);
    const SgprNetwork network(weights);
    (void)network;
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
