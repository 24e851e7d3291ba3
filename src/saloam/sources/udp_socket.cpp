#include "saloam/sources/udp_socket.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>

#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace saloam {
namespace {

constexpr std::string_view kScheme = "udp://";
constexpr std::size_t kMaxDatagram = 65535;

InputError bad_url(std::string_view text, std::string_view problem) {
  return InputError(std::string(text), fmt::format("{}: a live source is udp://[ADDRESS]:PORT, e.g. udp://:7502, "
                                                   "udp://0.0.0.0:7502, udp://127.0.0.1:2368 (ADDRESS a dotted IPv4 "
                                                   "address, PORT 0-65535)",
                                                   problem));
}

sockaddr_in socket_address(const UdpAddress& a) {
  sockaddr_in s{};
  s.sin_family = AF_INET;
  s.sin_addr.s_addr = htonl(a.ipv4);
  s.sin_port = htons(a.port);
  return s;
}

}  // namespace

std::string UdpAddress::url() const {
  in_addr a{};
  a.s_addr = htonl(ipv4);
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &a, text, sizeof text);
  return fmt::format("udp://{}:{}", text, port);
}

bool is_udp_url(std::string_view text) { return text.starts_with(kScheme); }

UdpAddress parse_udp_url(std::string_view text) {
  if (!is_udp_url(text)) throw bad_url(text, "not a udp:// address");
  const std::string_view rest = text.substr(kScheme.size());
  const auto colon = rest.rfind(':');
  if (colon == std::string_view::npos) throw bad_url(text, "no port");
  const std::string host(rest.substr(0, colon));
  const std::string_view port = rest.substr(colon + 1);
  UdpAddress address;
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (port.empty() || ec != std::errc() || end != port.data() + port.size() || value > 65535) {
    throw bad_url(text, fmt::format("port '{}' is not a number of 0-65535", port));
  }
  address.port = static_cast<std::uint16_t>(value);
  if (host.empty()) return address;
  in_addr a{};
  if (inet_pton(AF_INET, host.c_str(), &a) != 1) {
    throw bad_url(text, fmt::format("'{}' is not a dotted IPv4 address", host));
  }
  address.ipv4 = ntohl(a.s_addr);
  return address;
}

UdpReceiver::UdpReceiver(const UdpAddress& address, int buffer_bytes) : bound_(address) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw InputError(address.url(), fmt::format("cannot open a UDP socket: {}", std::strerror(errno)));
  // Sensors send 10-20 frames a second in bursts of packets: a large buffer
  // holds them while this reader is busy. The kernel caps SO_RCVBUF at
  // net.core.rmem_max (208 KiB unless raised: some 50 ms of an HDL-64E's
  // packets); with CAP_NET_ADMIN (root) SO_RCVBUFFORCE passes the cap. The
  // kernel reports twice what it keeps, for its bookkeeping.
  if (::setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &buffer_bytes, sizeof buffer_bytes) != 0) {
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &buffer_bytes, sizeof buffer_bytes);
  }
  socklen_t length = sizeof buffer_bytes_;
  ::getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &buffer_bytes_, &length);
  const sockaddr_in s = socket_address(address);
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&s), sizeof s) != 0) {
    const int error = errno;
    ::close(fd_);
    throw InputError(address.url(), fmt::format("cannot listen there: {}{}", std::strerror(error),
                                                error == EADDRINUSE ? " (another program receives on that port)"
                                                : error == EADDRNOTAVAIL ? " (no interface of this machine has that address)"
                                                                         : ""));
  }
  sockaddr_in bound{};
  length = sizeof bound;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &length);
  bound_.port = ntohs(bound.sin_port);
}

UdpReceiver::~UdpReceiver() {
  if (fd_ >= 0) ::close(fd_);
}

bool UdpReceiver::wait(std::chrono::milliseconds timeout) const {
  pollfd p{fd_, POLLIN, 0};
  return ::poll(&p, 1, static_cast<int>(timeout.count())) > 0 && (p.revents & POLLIN) != 0;
}

bool UdpReceiver::receive(std::vector<std::uint8_t>& payload) const {
  payload.resize(kMaxDatagram);
  const ssize_t n = ::recv(fd_, payload.data(), payload.size(), MSG_DONTWAIT);
  if (n < 0) {
    payload.clear();
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return false;
    throw InputError(bound_.url(), fmt::format("cannot receive: {}", std::strerror(errno)));
  }
  payload.resize(static_cast<std::size_t>(n));
  return true;
}

UdpSender::UdpSender(const UdpAddress& to) : to_(to) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw InputError(to.url(), fmt::format("cannot open a UDP socket: {}", std::strerror(errno)));
}

UdpSender::~UdpSender() {
  if (fd_ >= 0) ::close(fd_);
}

void UdpSender::send(std::span<const std::uint8_t> payload) const {
  const sockaddr_in s = socket_address(to_);
  if (::sendto(fd_, payload.data(), payload.size(), 0, reinterpret_cast<const sockaddr*>(&s), sizeof s) < 0) {
    throw InputError(to_.url(), fmt::format("cannot send a {}-byte datagram: {}", payload.size(), std::strerror(errno)));
  }
}

}  // namespace saloam
