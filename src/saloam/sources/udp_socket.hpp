#pragma once
// UDP over POSIX sockets (IPv4), for live sensor packets and their replay:
//   udp://[ADDRESS]:PORT  the address of a live source: ADDRESS a dotted IPv4
//                         address (0.0.0.0 or empty: every interface), PORT
//                         0..65535 (0 when listening: a free port the system
//                         picks, said by UdpReceiver::address()).
//   UdpReceiver           a bound socket with a large receive buffer, polled
//                         with a timeout so that its reader can look at the
//                         clock and the stop flag between datagrams.
//   UdpSender             datagrams to one address (saloam replay).

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace saloam {

struct UdpAddress {
  std::uint32_t ipv4 = 0;  ///< host order; 0 = every interface
  std::uint16_t port = 0;
  /// "udp://127.0.0.1:2368"
  [[nodiscard]] std::string url() const;
};

/// Whether `text` names a live source (begins with "udp://").
[[nodiscard]] bool is_udp_url(std::string_view text);
/// `udp://:7502`, `udp://0.0.0.0:7502`, `udp://127.0.0.1:2368`; InputError
/// naming `text` and the expected form when it is none of these.
[[nodiscard]] UdpAddress parse_udp_url(std::string_view text);

class UdpReceiver {
 public:
  /// Binds `address` and asks for a receive buffer of `buffer_bytes` (past
  /// net.core.rmem_max where the process may: root);
  /// InputError naming the URL when the socket cannot be bound (the port in
  /// use, an address of no interface here, a port below 1024 without rights).
  UdpReceiver(const UdpAddress& address, int buffer_bytes);
  ~UdpReceiver();
  UdpReceiver(const UdpReceiver&) = delete;
  UdpReceiver& operator=(const UdpReceiver&) = delete;

  /// Whether a datagram is waiting, after waiting at most `timeout`.
  [[nodiscard]] bool wait(std::chrono::milliseconds timeout) const;
  /// The next waiting datagram's payload into `payload` (resized to it);
  /// false when none is waiting. InputError on a socket error.
  bool receive(std::vector<std::uint8_t>& payload) const;

  /// The address bound (the port the system chose for port 0).
  [[nodiscard]] const UdpAddress& address() const { return bound_; }
  /// The receive buffer the kernel granted, as it reports it: twice what it
  /// keeps for packets [bytes].
  [[nodiscard]] int buffer_bytes() const { return buffer_bytes_; }

 private:
  int fd_ = -1;
  UdpAddress bound_;
  int buffer_bytes_ = 0;
};

class UdpSender {
 public:
  /// InputError naming the URL when no socket can be opened.
  explicit UdpSender(const UdpAddress& to);
  ~UdpSender();
  UdpSender(const UdpSender&) = delete;
  UdpSender& operator=(const UdpSender&) = delete;
  /// Sends one datagram; InputError naming the address when it cannot be sent.
  void send(std::span<const std::uint8_t> payload) const;

 private:
  int fd_ = -1;
  UdpAddress to_;
};

}  // namespace saloam
