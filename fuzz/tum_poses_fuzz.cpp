// TUM trajectories (read_tum_trajectory): t x y z qx qy qz qw per line.

#include <cmath>
#include <sstream>

#include "pose_checks.hpp"
#include "saloam/io/trajectory_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  const std::filesystem::path file = "trajectory.tum";
  const std::string text = fuzz::as_text(data, size);
  try {
    std::istringstream in(text);
    fuzz::check_trajectory(read_tum_trajectory(in, file));
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
