// Velodyne .bin scans, alone or with their .label file (parse_scan). The
// first byte picks how the rest is used: a scan only, a scan and labels split
// at the point count (counts agree), or split anywhere (counts may differ).

#include <cmath>

#include "fuzz_support.hpp"
#include "saloam/io/scan_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  if (size == 0) return 0;
  const std::uint8_t mode = data[0] % 3;
  const auto rest = fuzz::as_bytes(data + 1, size - 1);
  const std::filesystem::path bin_file = "000000.bin", label_file = "000000.label";
  std::optional<std::span<const std::byte>> labels;
  auto bin = rest;
  if (mode == 1) {  // 16 bytes of point, 4 of label
    const std::size_t points = rest.size() / 20;
    bin = rest.first(16 * points);
    labels = rest.subspan(16 * points);
  } else if (mode == 2 && !rest.empty()) {
    const std::size_t cut = rest.size() * static_cast<std::size_t>(data[size - 1]) / 256;
    bin = rest.first(cut);
    labels = rest.subspan(cut, rest.size() - 1 - cut);
  }
  try {
    ScanReadStats stats;
    const LabelledCloud cloud = parse_scan(bin, bin_file, labels, label_file, &stats);
    SALOAM_FUZZ_CHECK(!cloud.empty());
    SALOAM_FUZZ_CHECK(stats.points_in_file * 16 == bin.size());
    SALOAM_FUZZ_CHECK(cloud.size() + stats.dropped_nonfinite + stats.dropped_out_of_range == stats.points_in_file);
    SALOAM_FUZZ_CHECK(cloud.has_labels == labels.has_value());
    SALOAM_FUZZ_CHECK(cloud.label.size() == cloud.size() && cloud.instance.size() == cloud.size() &&
                      cloud.remission.size() == cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      SALOAM_FUZZ_CHECK(cloud.points[i].allFinite());
      SALOAM_FUZZ_CHECK(cloud.points[i].cwiseAbs().maxCoeff() <= kMaxScanCoordinate);
      SALOAM_FUZZ_CHECK(std::isfinite(cloud.remission[i]));
    }
  } catch (const InputError& e) {
    const bool names_bin = e.file() == bin_file;
    fuzz::check_names_input(e, names_bin ? bin_file : label_file);
  }
  return 0;
}
