#pragma once
// A sensor's packet capture (.pcap, libpcap's format; pcapng too) as a
// FrameSource. The capture's UDP datagrams (sensors/pcap_reader.hpp) go to
// the decoder of the sensor that sent them:
//   Ouster    lidar packets (by their size, the metadata's udp_port_lidar
//             by default 7502; IMU packets are left out) through
//             sensors/ouster_*.hpp, which needs the sensor's metadata JSON:
//             SourceOptions::metadata (--metadata), else NAME.json beside
//             NAME.pcap, else the one .json beside it whose name begins the
//             capture's (OS-1-128_v2.3.0_1024x10.json for
//             OS-1-128_v2.3.0_1024x10_lb_n3.pcap; digests left out).
//             A frame is one frame id; its time [s] is its first valid
//             column's timestamp (the sensor's clock); each point's time is
//             its column's, relative to that. First returns only.
//             Frames whose sensor times do not increase (a clock reset) make
//             the source take the capture's times instead (said in a note).
//   Velodyne  1206-byte data packets (port 2368) of a VLP-16, HDL-32E or
//             HDL-64E through sensors/velodyne_*.hpp; an HDL-64E needs its
//             calibration (--metadata CALIB.yaml, else NAME.yaml beside).
// Opening the capture reads it once, keeping where each frame's packets lie
// (file offsets), not the packets: any frame is served again by seeking
// there, one frame's packets in memory at a time.
// Points are in the sensor frame [m] (x forward, z up), with ring (beam
// index) and per-point times; remission is reflectivity (Ouster) or
// intensity (Velodyne), 0..255, divided by 255 (said in the notes and the
// run's log line). No labels, calibration or reference poses: a capture runs
// in the LiDAR frame.
// info().notes say the sensor, its firmware and packet profile, columns and
// beams, the packets read and what was wrong with any (wrong size, late,
// missing columns), and where the metadata came from.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saloam/io/frame_source.hpp"
#include "saloam/io/intensity_scale.hpp"
#include "saloam/sensors/pcap_reader.hpp"
#include "saloam/sources/source_options.hpp"

namespace saloam {

/// Where one frame's packets lie in the capture, and what it is.
struct CaptureFrame {
  std::int64_t first_offset = 0;  ///< file offset of its first packet's record
  std::int64_t last_offset = 0;   ///< and of its last
  double time = 0.0;              ///< [s] the sensor's clock
  double capture_time = 0.0;      ///< [s since the epoch] its first packet's capture time
  std::uint64_t tag = 0;          ///< the decoder's: Ouster frame id, Velodyne sweeps to skip
};

/// A sensor's decoder behind PcapSource (sources/pcap_source.cpp has the
/// Ouster and Velodyne ones).
class CaptureDecoder {
 public:
  virtual ~CaptureDecoder() = default;
  /// Index pass: every datagram of the capture in order; frames completed go to `done`.
  virtual void index(const UdpDatagram& datagram, std::vector<CaptureFrame>& done) = 0;
  /// Index pass: the capture ended.
  virtual void index_end(std::vector<CaptureFrame>& done) = 0;
  /// Frame `frame` read again from `reader` (already at frame.first_offset);
  /// remission as stored (0..255).
  virtual LabelledCloud read(PcapReader& reader, const CaptureFrame& frame) = 0;
  /// What `saloam info` lists: sensor, mode, packets, problems.
  [[nodiscard]] virtual std::vector<std::string> notes() const = 0;
  /// "x y z reflectivity ring t", ...
  [[nodiscard]] virtual std::string point_fields() const = 0;
  /// What remission is made of: "Ouster REFLECTIVITY (8 bits)", ...
  [[nodiscard]] virtual std::string intensity_field() const = 0;
};

/// The metadata (Ouster .json) or calibration (Velodyne .yaml) a capture is
/// read with: `given` when set, else as said above; nullopt when none is found.
[[nodiscard]] std::optional<std::filesystem::path> find_capture_metadata(
    const std::filesystem::path& capture, const std::optional<std::filesystem::path>& given);

class PcapSource final : public FrameSource {
 public:
  /// InputError naming the capture (or the metadata file) when it cannot be
  /// read, holds no frame, or its sensor cannot be told; naming the labels
  /// folder when SourceOptions::labels is given (a capture's points have no
  /// file order to pair labels with).
  PcapSource(std::filesystem::path capture, const SourceOptions& options);
  ~PcapSource() override;

  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  LabelledCloud scan(std::size_t i) override;

  [[nodiscard]] const std::vector<CaptureFrame>& frames() const { return frames_; }

 private:
  void index_capture();

  void read_imu(const std::filesystem::path& metadata);

  std::filesystem::path capture_;
  std::unique_ptr<PcapReader> reader_;
  std::unique_ptr<CaptureDecoder> decoder_;
  std::vector<CaptureFrame> frames_;
  IntensityScale intensity_;
  SourceInfo info_;
};

}  // namespace saloam
