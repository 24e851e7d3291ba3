// KITTI calib.txt (read_velo_to_cam): the Tr: line, a bare 12-number line,
// or the per-sequence "NN: ..." list (the first byte picks a sequence, or
// none).

#include <sstream>

#include "pose_checks.hpp"
#include "saloam/io/calibration.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  if (size == 0) return 0;
  const std::filesystem::path file = "calib.txt";
  const int sequence = data[0] < 128 ? -1 : data[0] % 22;
  std::istringstream in(fuzz::as_text(data + 1, size - 1));
  try {
    fuzz::check_rigid(read_velo_to_cam(in, file, sequence));
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
