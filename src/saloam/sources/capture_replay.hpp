#pragma once
// A packet capture's UDP payloads sent to an address at the capture's own
// pace (`saloam replay CAPTURE.pcap udp://127.0.0.1:2368 --rate 10`): what a
// live run (sources/live_udp_source.hpp) receives from the sensor, for tests
// and for trying a live run without one. Datagram k leaves at
// start + (t_k - t_0) / rate, t_k its capture time; one that is late (the
// sender was busy) leaves at once, so the whole keeps the capture's pace.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>

#include "saloam/sources/udp_socket.hpp"

namespace saloam {

struct ReplayOptions {
  double rate = 1.0;                  ///< > 0: the capture's pace times this
  std::optional<std::uint16_t> port;  ///< only the datagrams the capture has to this port (an Ouster's lidar packets, not its IMU's)
};

struct ReplayResult {
  std::size_t datagrams = 0;   ///< sent
  std::size_t bytes = 0;       ///< of payload sent
  double capture_seconds = 0;  ///< from the first datagram sent to the last, in the capture
  double seconds = 0;          ///< taken to send them
  bool interrupted = false;    ///< Ctrl-C ended it
};

/// Sends `capture`'s datagrams to `to` as said above; stops early on Ctrl-C
/// (the stop flag). InputError naming the capture when it cannot be read or
/// holds no datagram to send, naming the address when one cannot be sent.
ReplayResult replay_capture(const std::filesystem::path& capture, const UdpAddress& to, const ReplayOptions& options);

}  // namespace saloam
