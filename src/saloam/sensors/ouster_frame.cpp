#include "saloam/sensors/ouster_frame.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace saloam {

const std::vector<std::uint32_t>* OusterScan::field(OusterField f) const {
  for (const auto& [name, values] : fields) {
    if (name == f) return &values;
  }
  return nullptr;
}

std::optional<std::uint64_t> OusterScan::first_valid_timestamp() const {
  for (std::size_t u = 0; u < status.size(); ++u) {
    if (status[u] & 1U) return timestamp[u];
  }
  return std::nullopt;
}

// ---------------------------------------------------------------- assembler

OusterFrameAssembler::OusterFrameAssembler(const OusterMetadata& metadata)
    : format_(metadata), width_(metadata.columns_per_frame), packets_per_frame_(metadata.packets_per_frame()) {}

void OusterFrameAssembler::start(std::uint32_t frame_id) {
  OusterScan s;
  s.frame_id = frame_id;
  s.width = width_;
  s.height = format_.pixels_per_column();
  s.timestamp.assign(width_, 0);
  s.measurement_id.assign(width_, 0);
  s.status.assign(width_, 0);
  for (const auto& f : format_.fields()) {
    if (!f.raw_word()) s.fields.emplace_back(f.field, std::vector<std::uint32_t>(std::size_t{s.height} * width_, 0));
  }
  current_ = std::move(s);
}

void OusterFrameAssembler::batch(std::span<const std::uint8_t> packet) {
  OusterScan& s = *current_;
  ++s.packets;
  for (std::uint32_t c = 0; c < format_.columns_per_packet(); ++c) {
    const std::uint32_t status = format_.col_status(packet, c);
    const std::uint16_t id = format_.col_measurement_id(packet, c);
    if ((status & 1U) == 0 || id >= width_) continue;  // not valid, or out of the frame: stays zero
    if (s.status[id] == 0) ++s.valid_columns;
    s.timestamp[id] = format_.col_timestamp(packet, c);
    s.measurement_id[id] = id;
    s.status[id] = status;
    for (auto& [f, values] : s.fields) {
      const OusterFieldLayout& layout = *format_.layout(f);
      for (std::uint32_t px = 0; px < s.height; ++px) values[std::size_t{px} * width_ + id] = format_.pixel(packet, c, px, layout);
    }
  }
}

void OusterFrameAssembler::finalize(std::vector<OusterScan>& done) {
  finished_id_ = current_->frame_id;
  done.push_back(std::move(*current_));
  current_.reset();
}

void OusterFrameAssembler::add(std::span<const std::uint8_t> packet, std::vector<OusterScan>& done) {
  if (!format_.check(packet).empty()) {
    ++bad_packets_;
    return;
  }
  const std::uint32_t id = format_.frame_id(packet);
  if (current_ && current_->frame_id != id) {
    if (format_.frame_id_difference(current_->frame_id, id) < 0) {
      ++dropped_packets_;  // an earlier frame's packet, late
      return;
    }
    finalize(done);  // a later frame began: this one will get no more packets
  }
  if (!current_) {
    if (finished_id_ && format_.frame_id_difference(*finished_id_, id) <= 0) {
      ++dropped_packets_;  // the frame finished already
      return;
    }
    start(id);
  }
  batch(packet);
  if (current_->packets >= packets_per_frame_) finalize(done);
}

std::optional<OusterScan> OusterFrameAssembler::finish() {
  std::optional<OusterScan> out = std::move(current_);
  current_.reset();
  return out;
}

// ---------------------------------------------------------------- points

OusterXyzLut::OusterXyzLut(const OusterMetadata& m) : width_(m.columns_per_frame) {
  const std::uint32_t h = m.pixels_per_column;
  const double n = m.beam_to_lidar(0, 3);
  const double z = m.beam_to_lidar(2, 3);
  const double beam_distance = z != 0.0 ? std::hypot(n, z) : n;
  const Eigen::Matrix3d rotation = m.lidar_to_sensor.topLeftCorner<3, 3>();
  const Eigen::Vector3d translation = m.lidar_to_sensor.topRightCorner<3, 1>();
  constexpr double kMetresPerMm = 0.001;
  constexpr double kDeg = std::numbers::pi / 180.0;
  direction_.resize(std::size_t{h} * width_);
  offset_.resize(std::size_t{h} * width_);
  for (std::uint32_t r = 0; r < h; ++r) {
    const double azimuth = -m.beam_azimuth_angles[r] * kDeg;
    const double altitude = m.beam_altitude_angles[r] * kDeg;
    for (std::uint32_t u = 0; u < width_; ++u) {
      const double encoder = 2.0 * std::numbers::pi - u * (2.0 * std::numbers::pi / width_);
      const Eigen::Vector3d d(std::cos(encoder + azimuth) * std::cos(altitude),
                              std::sin(encoder + azimuth) * std::cos(altitude), std::sin(altitude));
      const Eigen::Vector3d o = Eigen::Vector3d(n * std::cos(encoder), n * std::sin(encoder), z) - beam_distance * d;
      const std::size_t i = std::size_t{r} * width_ + u;
      direction_[i] = kMetresPerMm * (rotation * d);
      offset_[i] = kMetresPerMm * (rotation * o + translation);
    }
  }
}

LabelledCloud ouster_cloud(const OusterScan& scan, const OusterXyzLut& lut, std::uint64_t frame_time_ns,
                           float reflectivity_divisor) {
  LabelledCloud cloud;
  const auto* range = scan.field(OusterField::kRange);
  const auto* reflectivity = scan.field(OusterField::kReflectivity);
  if (!range) return cloud;
  cloud.reserve(range->size());
  cloud.ring.reserve(range->size());
  cloud.time.reserve(range->size());
  for (std::uint32_t r = 0; r < scan.height; ++r) {
    for (std::uint32_t u = 0; u < scan.width; ++u) {
      const std::size_t i = std::size_t{r} * scan.width + u;
      if ((*range)[i] == 0) continue;
      const float value = reflectivity ? static_cast<float>((*reflectivity)[i]) : 0.0F;
      cloud.points.push_back(lut.point(r, u, (*range)[i]).cast<float>());
      cloud.remission.push_back(value / reflectivity_divisor);
      cloud.label.push_back(0);
      cloud.instance.push_back(0);
      cloud.ring.push_back(static_cast<std::uint16_t>(r));
      const auto dt = static_cast<std::int64_t>(scan.timestamp[u] - frame_time_ns);
      cloud.time.push_back(static_cast<float>(static_cast<double>(dt) * 1e-9));
    }
  }
  return cloud;
}

}  // namespace saloam
