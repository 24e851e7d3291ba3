// MCAP files (io/mcap.hpp): the bytes as a file, opened (indexed through a
// summary, or read linearly when there is none or the file is cut short),
// every topic selected and every message read, PointCloud2 messages parsed
// from CDR. Each step returns what its contract says or an InputError
// naming the file.

#include "fuzz_scratch.hpp"
#include "point_cloud_checks.hpp"
#include "saloam/io/mcap.hpp"
#include "saloam/io/pointcloud2.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  static const fuzz::ScratchFile scratch(".mcap");
  const std::filesystem::path& file = scratch.holding(data, size);
  try {
    McapReader mcap(file);
    for (const StoredTopic& topic : mcap.topics()) {
      const auto times = mcap.select(topic.name);
      SALOAM_FUZZ_CHECK(times.size() == topic.messages);
      for (std::size_t k = 0; k < times.size(); ++k) {
        try {
          const auto message = mcap.message(k, 1u << 20);
          if (topic.type != kRos2PointCloud2Type) continue;
          fuzz::check_decoded_cloud(parse_pointcloud2_cdr(message, file, "message").decoded);
        } catch (const InputError& e) {
          fuzz::check_names_input(e, file);
        }
      }
    }
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
