#pragma once
// A sensor's UDP packets in, whole frames out: the frame assembly that a
// packet capture (sources/pcap_source.hpp, reading a frame's packets again)
// and a live UDP source (sources/live_udp_source.hpp, packets as they come)
// share. Pure (no I/O): payloads in, points with rings and times out.
//   OusterPacketFramer    lidar packets batched by frame id
//                         (OusterFrameAssembler), a frame's points by the
//                         SDK's XYZ lookup (ouster_cloud); its time the first
//                         valid column's timestamp; frames without a valid
//                         column are left out (no time, no points).
//   VelodynePacketFramer  1206-byte data packets cut into sweeps behind the
//                         sensor (VelodyneFrameAssembler); frames without a
//                         point are left out.
// Remission is as sent (0..255): the source divides it (io/intensity_scale.hpp).

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/sensors/ouster_frame.hpp"
#include "saloam/sensors/velodyne_frame.hpp"

namespace saloam {

/// One frame made of a sensor's packets.
struct PacketFrame {
  LabelledCloud cloud;  ///< sensor frame [m]; ring, per-point time [s] since `time`; remission 0..255
  double time = 0.0;    ///< [s] the sensor's clock
  std::size_t packets = 0;
  /// Packets it lacks, as far as they tell: Velodyne, gaps in the packet
  /// timestamps while it was filled; Ouster, the column window's packets
  /// that did not come. Lost on the way, or in a receive buffer that overflowed.
  std::size_t missing_packets = 0;
};

class PacketFramer {
 public:
  virtual ~PacketFramer() = default;
  /// One UDP payload sent to `port`; the frames it completes go to `done`.
  /// Payloads that are no data packet of the sensor are counted and left out.
  virtual void add(std::span<const std::uint8_t> payload, std::uint16_t port, std::vector<PacketFrame>& done) = 0;
  /// The frame being filled when the packets end (the capture or the stream did).
  virtual void finish(std::vector<PacketFrame>& done) = 0;
  /// Forgets the frame being filled and the packets' order (the counts
  /// stay): the next packet may begin any frame (a capture's frame read again).
  virtual void restart() = 0;
  /// "123 lidar packets, 0 of the wrong size, 0 late", for logs and summaries.
  [[nodiscard]] virtual std::string packet_counts() const = 0;
  /// "x y z reflectivity ring t", ...
  [[nodiscard]] virtual std::string point_fields() const = 0;
  /// What remission is made of: "Ouster REFLECTIVITY, 8 bits", ...
  [[nodiscard]] virtual std::string intensity_field() const = 0;
};

class OusterPacketFramer final : public PacketFramer {
 public:
  explicit OusterPacketFramer(const OusterMetadata& metadata);
  /// Lidar packets: those sent to the metadata's udp_port_lidar, or of the
  /// profile's lidar packet size (captures of a sensor sending elsewhere).
  void add(std::span<const std::uint8_t> payload, std::uint16_t port, std::vector<PacketFrame>& done) override;
  void finish(std::vector<PacketFrame>& done) override;
  void restart() override;
  [[nodiscard]] std::string packet_counts() const override;
  [[nodiscard]] std::string point_fields() const override { return "x y z reflectivity ring t"; }
  [[nodiscard]] std::string intensity_field() const override { return "Ouster REFLECTIVITY, 8 bits"; }

  [[nodiscard]] bool is_lidar(std::span<const std::uint8_t> payload, std::uint16_t port) const;
  [[nodiscard]] const OusterPacketFormat& format() const { return assembler_.format(); }

 private:
  void emit(std::vector<PacketFrame>& done);

  OusterMetadata metadata_;
  OusterXyzLut lut_;
  OusterFrameAssembler assembler_;
  std::vector<OusterScan> scans_;
  std::size_t lidar_packets_ = 0, bad_packets_ = 0, late_packets_ = 0;  ///< before the last restart()
};

class VelodynePacketFramer final : public PacketFramer {
 public:
  explicit VelodynePacketFramer(VelodyneDecoder decoder);
  /// Data packets are the 1206-byte payloads (whatever the port: position
  /// packets are 512 bytes).
  void add(std::span<const std::uint8_t> payload, std::uint16_t port, std::vector<PacketFrame>& done) override;
  /// The same from block `first_block` on (a capture's frame read again from
  /// the middle of the packet where it began).
  void add_from_block(std::span<const std::uint8_t> payload, std::size_t first_block, std::vector<PacketFrame>& done);
  void finish(std::vector<PacketFrame>& done) override;
  void restart() override;
  [[nodiscard]] std::string packet_counts() const override;
  [[nodiscard]] std::string point_fields() const override { return "x y z intensity ring t"; }
  [[nodiscard]] std::string intensity_field() const override { return "Velodyne intensity, 8 bits"; }

 private:
  void emit(std::vector<PacketFrame>& done);

  VelodyneFrameAssembler assembler_;
  std::vector<VelodyneFrame> frames_;
  std::size_t packets_ = 0;
  std::size_t bad_packets_ = 0, missing_packets_ = 0;  ///< before the last restart()
};

}  // namespace saloam
