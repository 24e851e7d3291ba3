#pragma once
// A sensor's UDP packets as they arrive (`saloam slam udp://:2368 --sensor
// vlp16`), as a live FrameSource (io/frame_source.hpp: info().live, frames
// through next_frame()). The packets go through the same frame assembly as
// a packet capture's (sensors/packet_frames.hpp), so a capture replayed to
// the address (`saloam replay`) gives the capture's frames, point for point:
//   Velodyne  --sensor vlp16|hdl32e|hdl64e: 1206-byte data packets; the
//             calibration from --metadata CALIB.yaml, else the model's
//             datasheet angles (the HDL-64E has none: --metadata required)
//   Ouster    --metadata META.json (the sensor's metadata; --sensor os1-64,
//             os1-128 or any): lidar packets of its profile
// A receiver thread reads the socket (a 64 MiB receive buffer asked for)
// and assembles frames; it never waits for the run: complete frames go
// through a bounded queue (sources/frame_queue.hpp) that drops the oldest
// whole frame when the run falls behind, and counts it. A frame whose time
// is not after the last queued one's (a sensor clock reset) is dropped and
// counted too: the runs need increasing times; so is a frame that lacks
// packets (PacketFrame::missing_packets: lost on the network, or in the
// receive buffer when the receiver fell behind the sensor): a run never
// gets part of a sweep. The first and last frames of a stream may still be
// part sweeps, begun or ended mid-turn, as a capture's are.
// The stream ends when no packet arrived for LiveOptions::idle_timeout_s
// (the frame being filled is then finished and served), or on Ctrl-C (the
// stop flag: queued frames are left unread). Times: the sensor's clock, as
// a capture's; remission divided by 255 (8-bit fields). No labels,
// calibration or reference: a live run works in the LiDAR frame.

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "saloam/io/frame_source.hpp"
#include "saloam/io/intensity_scale.hpp"
#include "saloam/sensors/packet_frames.hpp"
#include "saloam/sources/frame_queue.hpp"
#include "saloam/sources/source_options.hpp"
#include "saloam/sources/udp_socket.hpp"

namespace saloam {

/// The frame assembly for the packets of options.live.sensor / options.metadata;
/// InputError naming `url` when the sensor is missing, unknown, or lacks the
/// metadata it needs. `notes` receives what was chosen (sensor, calibration).
std::unique_ptr<PacketFramer> live_packet_framer(const std::string& url, const SourceOptions& options,
                                                 std::vector<std::string>& notes);

class LiveUdpSource final : public FrameSource {
 public:
  /// Listens on `url` (udp_socket.hpp's forms) and starts receiving;
  /// InputError naming the URL for a malformed one, a port in use, a missing
  /// --sensor or metadata, or labels asked for (live packets carry none).
  LiveUdpSource(const std::string& url, const SourceOptions& options);
  ~LiveUdpSource() override;
  LiveUdpSource(const LiveUdpSource&) = delete;
  LiveUdpSource& operator=(const LiveUdpSource&) = delete;

  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  /// std::logic_error: a live source serves its frames through next_frame() only.
  LabelledCloud scan(std::size_t i) override;
  /// The next frame as it comes (waits for it); none once the stream ended.
  /// Frames are served once, in order (std::logic_error otherwise).
  std::optional<SourceFrame> next_frame(std::size_t i) override;
  [[nodiscard]] std::optional<StreamStats> stream_stats() const override;
  void close_stream() override;

  /// The address listened on (the port the system chose for port 0).
  [[nodiscard]] const UdpAddress& address() const { return receiver_.address(); }

 private:
  /// info_: the address, the sensor's `notes`, the fields, what the receiver and queue are.
  void describe(std::vector<std::string> notes);
  void receive_loop();
  /// The datagrams waiting (up to kDrainLimit) through the framer, each
  /// frame queued as soon as made; true when any came.
  bool drain(std::vector<PacketFrame>& made);
  void queue(std::vector<PacketFrame>& made);
  /// Ends the stream: the framer's last frame queued unless `interrupted`.
  void end_stream(const std::string& reason, bool interrupted);
  /// The latency of the frame served last, the run asking again at `now` (under run_mutex_).
  void note_latency(std::chrono::steady_clock::time_point now);

  UdpReceiver receiver_;
  std::unique_ptr<PacketFramer> framer_;
  IntensityScale intensity_;
  LiveOptions options_;
  SourceInfo info_;
  FrameQueue queue_;

  std::atomic<bool> closing_{false};
  std::thread thread_;
  // The receiver thread's, read by stream_stats() under stats_mutex_.
  mutable std::mutex stats_mutex_;
  std::size_t packets_ = 0;
  std::size_t frames_made_ = 0;
  std::size_t out_of_order_ = 0;
  std::size_t incomplete_ = 0;
  std::optional<double> last_time_;
  // The run's side (a segmentation stage's workers ask from their threads).
  mutable std::mutex run_mutex_;
  std::size_t served_ = 0;
  std::optional<std::chrono::steady_clock::time_point> last_completed_;  ///< the frame served last
  std::vector<double> latency_ms_;
};

}  // namespace saloam
