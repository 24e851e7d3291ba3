// PCD files (parse_pcd): ascii, binary and binary_compressed (LZF) data
// behind a text header of any fields; the first byte picks whether the scan
// has a timestamp for absolute per-point times.

#include "point_cloud_checks.hpp"
#include "saloam/io/pcd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  if (size == 0) return 0;
  const std::filesystem::path file = "000000.pcd";
  const std::optional<double> stamp = data[0] % 2 ? std::optional<double>(1317042145.5) : std::nullopt;
  try {
    fuzz::check_decoded_cloud(parse_pcd(fuzz::as_bytes(data + 1, size - 1), file, stamp));
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
