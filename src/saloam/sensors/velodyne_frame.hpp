#pragma once
// Velodyne data packets gathered into sweeps: pure (packet bytes in, frames
// out), for captures and, later, live UDP. A frame ends where the blocks'
// azimuth passes the cut angle, 180 deg by default: behind the sensor, where
// KITTI's scans and the simulator's sweeps begin and end (Velodyne azimuths
// turn clockwise from the front). The cut falls between two blocks, so a
// packet can end one frame and begin the next; the first and last frames of
// a capture can be partial sweeps. Times: packet timestamps are
// microseconds past the hour (the sensor's clock, GPS-synchronised or
// free-running); they are unwrapped across hours here. A frame's time [s] is
// its first block's firing; each point's time is its firing's, relative to
// that (velodyne_packet.hpp's timing).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/sensors/velodyne_packet.hpp"

namespace saloam {

struct VelodyneFrame {
  LabelledCloud cloud;  ///< remission 0..255 as sent, ring, time
  double time = 0.0;    ///< [s] the sensor's clock, unwrapped
  std::size_t packets = 0;
  /// Packets missing by the timestamps' gaps while it was filled, or just
  /// before it began (see missing_packets()): a gap between two frames
  /// counts for both.
  std::size_t missing_packets = 0;
};

class VelodyneFrameAssembler {
 public:
  explicit VelodyneFrameAssembler(VelodyneDecoder decoder, double cut_azimuth_deg = 180.0);

  /// Adds one packet's payload, from block `first_block` on (a frame read
  /// again from the middle of a packet); frames it ends go to `done`. A
  /// packet that check_velodyne_packet refuses is counted and left out.
  void add(std::span<const std::uint8_t> packet, std::vector<VelodyneFrame>& done, std::size_t first_block = 0);
  /// The frame being filled, if any (the capture ended).
  std::optional<VelodyneFrame> finish();

  /// Frames begun so far (a frame begins with the first packet and at every cut).
  [[nodiscard]] std::size_t frames_begun() const { return frames_begun_; }
  /// The block of the last packet added where its last frame began.
  [[nodiscard]] std::size_t last_start_block() const { return last_start_block_; }
  [[nodiscard]] std::size_t bad_packets() const { return bad_packets_; }
  /// Packets the timestamps say are missing (gaps over 1.5 packet periods).
  [[nodiscard]] std::size_t missing_packets() const { return missing_packets_; }
  [[nodiscard]] const VelodyneDecoder& decoder() const { return decoder_; }

 private:
  [[nodiscard]] double unwrap_us(std::uint32_t timestamp_us);
  /// Packets missing before this one (counted, and charged to the frame being filled); 0 without a gap.
  std::size_t count_gap(double packet_us, bool dual);
  void begin(double time_s, std::size_t block, std::vector<VelodyneFrame>& done);

  VelodyneDecoder decoder_;
  std::uint16_t cut_ = 18000;  ///< [0.01 deg]
  std::optional<VelodyneFrame> current_;
  std::optional<std::uint16_t> last_relative_azimuth_;
  std::optional<std::uint32_t> last_timestamp_us_;
  double hours_us_ = 0.0;
  std::optional<double> last_packet_us_;
  std::vector<VelodyneReturn> returns_;
  std::size_t frames_begun_ = 0;
  std::size_t last_start_block_ = 0;
  std::size_t bad_packets_ = 0;
  std::size_t missing_packets_ = 0;
};

}  // namespace saloam
