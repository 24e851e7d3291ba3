// PLY files (parse_ply): ascii and binary of either byte order, elements
// before and after the vertices.

#include "point_cloud_checks.hpp"
#include "saloam/io/ply.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  const std::filesystem::path file = "000000.ply";
  try {
    fuzz::check_decoded_cloud(parse_ply(fuzz::as_bytes(data, size), file));
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
