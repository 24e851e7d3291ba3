// ROS 1 bags (RosbagSource over Debian's rosbag_storage): the bytes after
// the "#ROSBAG V2.0" magic, written to a temporary file (rosbag reads only
// files), opened, and every scan of the picked topic read. Built only with
// rosbag_storage.

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <system_error>

#include <fmt/format.h>

#include "point_cloud_checks.hpp"
#include "saloam/sources/rosbag_source.hpp"

namespace {
/// The file each input is written to: one per process, removed when it ends.
struct ScratchBag {
  std::filesystem::path path = std::filesystem::temp_directory_path() / fmt::format("saloam_fuzz_{}.bag", ::getpid());
  ScratchBag() = default;
  ScratchBag(const ScratchBag&) = delete;
  ScratchBag& operator=(const ScratchBag&) = delete;
  ~ScratchBag() {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  }
};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  static const ScratchBag scratch;
  const std::filesystem::path& file = scratch.path;
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out << kRosbagMagic;
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    RosbagSource bag(file, {});
    const auto& times = bag.info().times;
    SALOAM_FUZZ_CHECK(bag.size() > 0 && times.size() == bag.size());
    for (std::size_t i = 0; i < bag.size(); ++i) {
      if (i > 0) SALOAM_FUZZ_CHECK(times[i] > times[i - 1]);
      try {
        const LabelledCloud cloud = bag.scan(i);
        SALOAM_FUZZ_CHECK(!cloud.empty());
      } catch (const InputError& e) {
        fuzz::check_names_input(e, file);
      }
    }
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
