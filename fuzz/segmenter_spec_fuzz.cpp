// Segmentation model descriptions (parse_segmenter_spec, what
// read_segmenter_spec reads files with). Accepted text must give a
// description whose values lie in their documented ranges and that survives
// segmenter_spec_yaml and back unchanged.

#include <cmath>

#include "fuzz_support.hpp"
#include "saloam/segmentation/segmenter_spec.hpp"

namespace {

void check_ranges(const saloam::SegmenterSpec& spec) {
  using saloam::RowMode;
  const auto& p = spec.projection;
  SALOAM_FUZZ_CHECK(p.columns >= 16 && p.columns <= 16384);
  SALOAM_FUZZ_CHECK(!p.channels.empty() && p.means.size() == p.channels.size() && p.stds.size() == p.channels.size());
  for (const float s : p.stds) SALOAM_FUZZ_CHECK(s > 0 && std::isfinite(s));
  for (const float m : p.means) SALOAM_FUZZ_CHECK(std::isfinite(m));
  if (p.row_mode == RowMode::kRing) {
    SALOAM_FUZZ_CHECK(!spec.beams.empty());
    for (const int b : spec.beams) SALOAM_FUZZ_CHECK(b >= 4 && b <= 1024);
  } else {
    SALOAM_FUZZ_CHECK(p.rows >= 4 && p.rows <= 1024 && p.fov_down_deg < p.fov_up_deg);
  }
  SALOAM_FUZZ_CHECK(spec.classes.size() >= 2 && spec.classes.front() == 0);
  SALOAM_FUZZ_CHECK(spec.knn.window % 2 == 1 && spec.knn.k >= 1 && spec.knn.k <= spec.knn.window * spec.knn.window);
  SALOAM_FUZZ_CHECK(spec.knn.cutoff > 0 && spec.knn.sigma > 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  const std::filesystem::path origin = "/models/model.yaml";
  SegmenterSpec spec;
  try {
    spec = parse_segmenter_spec(fuzz::as_text(data, size), origin);
  } catch (const InputError& e) {
    SALOAM_FUZZ_CHECK(e.file() == origin);
    return 0;
  }
  check_ranges(spec);
  const std::string yaml = segmenter_spec_yaml(spec, origin.parent_path());
  const SegmenterSpec again = parse_segmenter_spec(yaml, origin);
  SALOAM_FUZZ_CHECK(segmenter_spec_yaml(again, origin.parent_path()) == yaml);
  return 0;
}
