// Velodyne data packets (sensors/velodyne_*.hpp): the first byte picks the
// model (VLP-16, HDL-32E with their datasheet angles, HDL-64E with a made-up
// calibration); the rest is a run of packets, each behind a 2-byte
// little-endian length, cut into sweeps by the frame assembler. With the
// first byte's top bit set the rest is a calibration YAML instead
// (parse_velodyne_calibration).

#include <cmath>
#include <numbers>

#include "fuzz_support.hpp"
#include "saloam/sensors/velodyne_frame.hpp"

namespace {

saloam::VelodyneDecoder decoder(std::uint8_t choice) {
  using namespace saloam;
  const VelodyneModel models[] = {VelodyneModel::kVlp16, VelodyneModel::kHdl32e, VelodyneModel::kHdl64e};
  const VelodyneModel model = models[choice % 3];
  if (auto nominal = nominal_velodyne_calibration(model)) return {model, *nominal};
  VelodyneCalibration c;
  for (int i = 0; i < 64; ++i) {
    VelodyneLaser l;
    l.vert_correction = (2.0 - 0.42 * i) * std::numbers::pi / 180.0;
    l.rot_correction = (i % 2 ? -0.08 : 0.05);
    l.dist_correction = 1.2 + 0.01 * (i % 7);
    l.dist_correction_x = l.dist_correction + 0.02;
    l.dist_correction_y = l.dist_correction - 0.02;
    l.vert_offset = 0.2;
    l.horiz_offset = i % 2 ? 0.026 : -0.026;
    c.lasers.push_back(l);
  }
  return {model, c};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  if (size == 0) return 0;
  if (data[0] & 0x80) {
    const std::filesystem::path file = "calibration.yaml";
    try {
      const VelodyneCalibration c = parse_velodyne_calibration(fuzz::as_text(data + 1, size - 1), file);
      SALOAM_FUZZ_CHECK(!c.lasers.empty() && c.lasers.size() <= 128);
    } catch (const InputError& e) {
      fuzz::check_names_input(e, file);
    }
    return 0;
  }
  VelodyneFrameAssembler assembler(decoder(data[0]));
  const std::size_t lasers = velodyne_lasers(assembler.decoder().model());
  std::vector<VelodyneFrame> frames;
  for (std::size_t at = 1; at + 2 <= size;) {
    const std::size_t n = std::min<std::size_t>(data[at] | (data[at + 1] << 8), size - at - 2);
    assembler.add({data + at + 2, n}, frames, data[at] % 13 == 0 ? data[at] % 12 : 0);
    at += 2 + n;
  }
  if (auto last = assembler.finish()) frames.push_back(std::move(*last));
  for (const auto& frame : frames) {
    const LabelledCloud& c = frame.cloud;
    SALOAM_FUZZ_CHECK(c.has_rings() || c.empty());
    SALOAM_FUZZ_CHECK(c.has_times() || c.empty());
    for (std::size_t i = 0; i < c.size(); ++i) {
      SALOAM_FUZZ_CHECK(c.points[i].allFinite() && c.points[i].norm() < 200.0F);  // 16-bit, 2 mm: < 131 m
      SALOAM_FUZZ_CHECK(c.ring[i] < lasers && c.remission[i] >= 0.0F && c.remission[i] <= 255.0F);
      SALOAM_FUZZ_CHECK(std::isfinite(c.time[i]));
    }
  }
  return 0;
}
