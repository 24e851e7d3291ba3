// KITTI raw text files: the first byte picks an oxts record (parse_oxts,
// then its pose), a timestamps file (parse_kitti_timestamps_ns) or
// calib_imu_to_velo.txt (parse_imu_to_velo).

#include <cmath>
#include <sstream>

#include "fuzz_support.hpp"
#include "pose_checks.hpp"
#include "saloam/io/kitti_raw.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  if (size == 0) return 0;
  const int mode = data[0] % 3;
  const std::filesystem::path file = mode == 0 ? "0000000000.txt" : mode == 1 ? "timestamps.txt" : "calib_imu_to_velo.txt";
  std::istringstream in(fuzz::as_text(data + 1, size - 1));
  try {
    if (mode == 0) {
      const OxtsRecord r = parse_oxts(in, file);
      SALOAM_FUZZ_CHECK(std::abs(r.lat) <= 85.0 && std::isfinite(r.lon) && std::isfinite(r.yaw));
      const auto poses = oxts_to_poses({r, r});
      SALOAM_FUZZ_CHECK(poses.size() == 2);
      SALOAM_FUZZ_CHECK(poses[1].translation().norm() < 1e-3 * (1.0 + std::abs(r.alt)));
    } else if (mode == 1) {
      const auto times = parse_kitti_timestamps_ns(in, file);
      for (std::size_t i = 1; i < times.size(); ++i) SALOAM_FUZZ_CHECK(times[i] > times[i - 1]);
    } else {
      fuzz::check_rigid(parse_imu_to_velo(in, file));
    }
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
