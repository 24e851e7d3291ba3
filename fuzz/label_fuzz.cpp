// SemanticKITTI .label files (parse_label_bytes): one uint32 per point.

#include <cstring>

#include "fuzz_support.hpp"
#include "saloam/io/scan_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  const std::filesystem::path file = "000000.label";
  try {
    const auto labels = parse_label_bytes(fuzz::as_bytes(data, size), file);
    SALOAM_FUZZ_CHECK(labels.size() * 4 == size);
    SALOAM_FUZZ_CHECK(labels.empty() || std::memcmp(labels.data(), data, size) == 0);
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
    SALOAM_FUZZ_CHECK(size % 4 != 0);
  }
  return 0;
}
