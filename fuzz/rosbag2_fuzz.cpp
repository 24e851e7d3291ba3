// rosbag2 sqlite3 databases (io/db3.hpp): the bytes as a .db3 file, opened
// through SQLite, every topic selected and every message read (a header's
// prefix, then whole), PointCloud2 messages parsed from CDR. Each step
// returns what its contract says or an InputError naming the file.

#include "fuzz_scratch.hpp"
#include "point_cloud_checks.hpp"
#include "saloam/io/db3.hpp"
#include "saloam/io/pointcloud2.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  static const fuzz::ScratchFile scratch(".db3");
  const std::filesystem::path& file = scratch.holding(data, size);
  try {
    Db3Reader db(file);
    for (const StoredTopic& topic : db.topics()) {
      const auto times = db.select(topic.name);
      for (std::size_t k = 0; k < times.size(); ++k) {
        try {
          const auto head = db.message(k, 64);
          SALOAM_FUZZ_CHECK(head.size() <= 64);
          const auto message = db.message(k, 1u << 20);
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
