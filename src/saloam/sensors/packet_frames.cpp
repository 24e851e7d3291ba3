#include "saloam/sensors/packet_frames.hpp"

#include <fmt/format.h>

namespace saloam {

// ------------------------------------------------------------------ Ouster

OusterPacketFramer::OusterPacketFramer(const OusterMetadata& metadata)
    : metadata_(metadata), lut_(metadata_), assembler_(metadata_) {}

bool OusterPacketFramer::is_lidar(std::span<const std::uint8_t> payload, std::uint16_t port) const {
  return port == metadata_.udp_port_lidar || payload.size() == assembler_.format().packet_size();
}

void OusterPacketFramer::add(std::span<const std::uint8_t> payload, std::uint16_t port, std::vector<PacketFrame>& done) {
  if (!is_lidar(payload, port)) return;  // IMU packets
  ++lidar_packets_;
  assembler_.add(payload, scans_);
  emit(done);
}

void OusterPacketFramer::finish(std::vector<PacketFrame>& done) {
  if (auto last = assembler_.finish()) scans_.push_back(std::move(*last));
  emit(done);
}

void OusterPacketFramer::emit(std::vector<PacketFrame>& done) {
  for (const OusterScan& scan : scans_) {
    const auto t0 = scan.first_valid_timestamp();
    if (!t0) continue;  // no valid column: no time, no point
    const std::size_t expected = metadata_.packets_per_frame();
    done.push_back({ouster_cloud(scan, lut_, *t0, 1.0F), static_cast<double>(*t0) * 1e-9, scan.packets,
                    expected > scan.packets ? expected - scan.packets : 0});
  }
  scans_.clear();
}

void OusterPacketFramer::restart() {
  bad_packets_ += assembler_.bad_packets();
  late_packets_ += assembler_.dropped_packets();
  assembler_ = OusterFrameAssembler(metadata_);
  scans_.clear();
}

std::string OusterPacketFramer::packet_counts() const {
  return fmt::format("{} lidar packets, {} of the wrong size, {} late (dropped)", lidar_packets_,
                     bad_packets_ + assembler_.bad_packets(), late_packets_ + assembler_.dropped_packets());
}

// ---------------------------------------------------------------- Velodyne

VelodynePacketFramer::VelodynePacketFramer(VelodyneDecoder decoder) : assembler_(std::move(decoder)) {}

void VelodynePacketFramer::add(std::span<const std::uint8_t> payload, std::uint16_t /*port*/,
                               std::vector<PacketFrame>& done) {
  add_from_block(payload, 0, done);
}

void VelodynePacketFramer::add_from_block(std::span<const std::uint8_t> payload, std::size_t first_block,
                                          std::vector<PacketFrame>& done) {
  if (payload.size() != kVelodynePacketBytes) return;  // position packets
  ++packets_;
  assembler_.add(payload, frames_, first_block);
  emit(done);
}

void VelodynePacketFramer::finish(std::vector<PacketFrame>& done) {
  if (auto last = assembler_.finish()) frames_.push_back(std::move(*last));
  emit(done);
}

void VelodynePacketFramer::emit(std::vector<PacketFrame>& done) {
  for (VelodyneFrame& frame : frames_) {
    if (frame.cloud.empty()) continue;
    done.push_back({std::move(frame.cloud), frame.time, frame.packets, frame.missing_packets});
  }
  frames_.clear();
}

void VelodynePacketFramer::restart() {
  bad_packets_ += assembler_.bad_packets();
  missing_packets_ += assembler_.missing_packets();
  assembler_ = VelodyneFrameAssembler(assembler_.decoder());
  frames_.clear();
}

std::string VelodynePacketFramer::packet_counts() const {
  return fmt::format("{} data packets, {} malformed, about {} missing (gaps in their timestamps)", packets_,
                     bad_packets_ + assembler_.bad_packets(), missing_packets_ + assembler_.missing_packets());
}

}  // namespace saloam
