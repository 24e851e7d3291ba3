#include "saloam/sources/velodyne_capture_writer.hpp"

#include <array>
#include <cmath>
#include <fstream>
#include <numbers>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/sensors/pcap_reader.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

constexpr double kPi = std::numbers::pi;

/// The ring (0 = top) of each channel in the model's firing order.
std::vector<std::size_t> ring_of_channel(VelodyneModel model, std::size_t lasers) {
  std::vector<std::size_t> out(lasers);
  for (std::size_t ch = 0; ch < lasers; ++ch) {
    if (model == VelodyneModel::kHdl64e) {
      out[ch] = ch;
    } else {  // interleaved from the bottom: lowest, middle, second lowest, ...
      const std::size_t rank_from_bottom = ch % 2 == 0 ? ch / 2 : lasers / 2 + ch / 2;
      out[ch] = lasers - 1 - rank_from_bottom;
    }
  }
  return out;
}

/// One sweep's returns by column and ring: raw distance and intensity.
struct SweepGrid {
  SweepGrid(std::size_t columns, std::size_t rings) : rings(rings), distance(columns * rings, 0), intensity(columns * rings, 0) {}
  std::size_t rings;
  std::vector<std::uint16_t> distance;
  std::vector<std::uint8_t> intensity;
};

SweepGrid grid_of(const LabelledCloud& cloud, const VelodyneSweepLayout& layout, std::size_t frame) {
  const auto columns = static_cast<std::size_t>(layout.azimuth_steps);
  const std::size_t rings = layout.elevation_deg.size();
  if (!cloud.has_rings() && !cloud.empty()) {
    throw InputError(fmt::format("frame {}", frame), "points without rings cannot be written as Velodyne packets");
  }
  SweepGrid grid(columns, rings);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = cloud.points[i].cast<double>();
    const double fraction = std::fmod(kPi - std::atan2(p.y(), p.x()) + 2 * kPi, 2 * kPi) / (2 * kPi);
    const auto column = static_cast<std::size_t>(std::lround(fraction * static_cast<double>(columns) - 0.5)) % columns;
    const double counts = std::round(p.norm() / kVelodyneDistanceUnit);
    if (cloud.ring[i] >= rings || counts < 1 || counts > 65535) continue;
    const std::size_t at = column * rings + cloud.ring[i];
    grid.distance[at] = static_cast<std::uint16_t>(counts);
    grid.intensity[at] = static_cast<std::uint8_t>(std::lround(std::clamp(cloud.remission[i], 0.0F, 1.0F) * 255.0F));
  }
  return grid;
}

/// Blocks into packets, packets into the capture.
class PacketStream {
 public:
  PacketStream(const fs::path& capture, VelodyneModel model) : writer_(capture), model_(model) {}

  /// A firing at `time` [s]: VLP-16 sequences fill half a block each.
  void add(const VelodyneFiring& firing, double time, bool second_sequence = false) {
    if (blocks_ == 0 && !second_sequence) first_time_ = time;
    if (second_sequence) {
      VelodyneFiring& block = pending_[blocks_ - 1];
      for (std::size_t ch = 0; ch < 16; ++ch) {
        block.distance[16 + ch] = firing.distance[ch];
        block.intensity[16 + ch] = firing.intensity[ch];
      }
    } else {
      pending_[blocks_++] = firing;
    }
    last_time_ = time;
    if (blocks_ == 12 && (model_ != VelodyneModel::kVlp16 || second_sequence)) flush();
  }
  /// Pads a last packet with empty firings, continuing the turn.
  void close(std::uint16_t azimuth_step) {
    std::uint16_t azimuth = blocks_ > 0 ? pending_[blocks_ - 1].azimuth : 0;
    while (blocks_ > 0 && blocks_ < 12) {
      VelodyneFiring empty;
      azimuth = static_cast<std::uint16_t>((azimuth + azimuth_step) % 36000);
      empty.azimuth = azimuth;
      empty.lower = model_ == VelodyneModel::kHdl64e && blocks_ % 2 == 1;
      pending_[blocks_++] = empty;
    }
    if (blocks_ == 12) flush();
    writer_.close();
  }

 private:
  void flush() {
    const double in_hour = std::fmod(first_time_, 3600.0);
    const auto stamp = static_cast<std::uint32_t>(std::llround(in_hour * 1e6)) % 3600000000U;
    const auto packet = encode_velodyne_packet(model_, pending_, stamp);
    writer_.write(last_time_, packet, kVelodyneDataPort);
    blocks_ = 0;
  }

  PcapWriter writer_;
  VelodyneModel model_;
  std::array<VelodyneFiring, 12> pending_{};
  std::size_t blocks_ = 0;
  double first_time_ = 0.0, last_time_ = 0.0;
};

void write_calibration(const fs::path& capture, VelodyneModel model, const VelodyneSweepLayout& layout) {
  VelodyneCalibration calibration;
  for (std::size_t ring : ring_of_channel(model, layout.elevation_deg.size())) {
    VelodyneLaser laser;
    laser.vert_correction = layout.elevation_deg[ring] * kPi / 180.0;
    calibration.lasers.push_back(laser);
  }
  fs::path file = capture;
  file.replace_extension(".yaml");
  std::ofstream out(file);
  out << velodyne_calibration_yaml(calibration);
  if (!out) throw InputError(file, "cannot write the calibration");
}

}  // namespace

VelodyneModel velodyne_model_for(std::size_t lasers) {
  for (auto m : {VelodyneModel::kVlp16, VelodyneModel::kHdl32e, VelodyneModel::kHdl64e}) {
    if (velodyne_lasers(m) == lasers) return m;
  }
  throw ConfigError(fmt::format("a Velodyne capture needs 16 (VLP-16), 32 (HDL-32E) or 64 (HDL-64E) lasers, not {}", lasers));
}

void write_velodyne_capture(FrameSource& in, const VelodyneSweepLayout& layout, const fs::path& capture) {
  const VelodyneModel model = velodyne_model_for(layout.elevation_deg.size());
  if (layout.azimuth_steps <= 0) throw ConfigError("a Velodyne capture needs azimuth steps");
  write_calibration(capture, model, layout);
  const auto channels = ring_of_channel(model, layout.elevation_deg.size());
  const auto columns = static_cast<std::size_t>(layout.azimuth_steps);
  PacketStream stream(capture, model);
  bool second_sequence = false;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const SweepGrid grid = grid_of(in.scan(i), layout, i);
    for (std::size_t c = 0; c < columns; ++c) {
      const double fraction = (static_cast<double>(c) + 0.5) / static_cast<double>(columns);
      const double time = in.info().times[i] + layout.sweep_period * fraction;
      const auto azimuth = static_cast<std::uint16_t>(std::lround(18000.0 + 36000.0 * fraction) % 36000);
      for (std::size_t half = 0; half < (model == VelodyneModel::kHdl64e ? 2U : 1U); ++half) {
        VelodyneFiring firing;
        firing.azimuth = azimuth;
        firing.lower = half == 1;
        for (std::size_t ch = 0; ch < std::min<std::size_t>(32, channels.size()); ++ch) {
          const std::size_t at = c * grid.rings + channels[ch + 32 * half];
          firing.distance[ch] = grid.distance[at];
          firing.intensity[ch] = grid.intensity[at];
        }
        stream.add(firing, time, model == VelodyneModel::kVlp16 && second_sequence);
        if (model == VelodyneModel::kVlp16) second_sequence = !second_sequence;
      }
    }
  }
  stream.close(static_cast<std::uint16_t>(std::lround(36000.0 / static_cast<double>(columns))));
}

}  // namespace saloam
