// KITTI pose files (read_kitti_poses) and the format-guessing
// read_trajectory, which takes them too.

#include <cmath>
#include <sstream>

#include "pose_checks.hpp"
#include "saloam/io/trajectory_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  const std::filesystem::path file = "poses.txt";
  const std::string text = fuzz::as_text(data, size);
  try {
    std::istringstream in(text);
    const auto poses = read_kitti_poses(in, file);
    SALOAM_FUZZ_CHECK(!poses.empty());
    for (const auto& T : poses) fuzz::check_rigid(T);
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  try {
    std::istringstream in(text);
    TrajectoryFormat format{};
    fuzz::check_trajectory(read_trajectory(in, file, &format));
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
