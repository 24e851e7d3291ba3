// KITTI times.txt (read_times): one increasing timestamp per line.

#include <cmath>
#include <sstream>

#include "fuzz_support.hpp"
#include "saloam/io/trajectory_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  const std::filesystem::path file = "times.txt";
  std::istringstream in(fuzz::as_text(data, size));
  try {
    const auto times = read_times(in, file);
    for (std::size_t i = 0; i < times.size(); ++i) {
      SALOAM_FUZZ_CHECK(std::isfinite(times[i]));
      if (i > 0) SALOAM_FUZZ_CHECK(times[i] > times[i - 1]);
    }
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
