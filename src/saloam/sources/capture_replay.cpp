#include "saloam/sources/capture_replay.hpp"

#include <chrono>
#include <thread>

#include <fmt/format.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/sensors/pcap_reader.hpp"

namespace saloam {
namespace {

using Clock = std::chrono::steady_clock;

/// When datagram time `t` leaves: `start` plus its offset in the capture divided by the rate.
Clock::time_point departure(Clock::time_point start, double t0, double t, double rate) {
  return start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>((t - t0) / rate));
}

}  // namespace

ReplayResult replay_capture(const std::filesystem::path& capture, const UdpAddress& to, const ReplayOptions& options) {
  if (!(options.rate > 0)) throw InputError(capture, fmt::format("replay rate {} is not above 0", options.rate));
  PcapReader reader(capture);
  const UdpSender sender(to);
  ReplayResult result;
  std::optional<double> t0;
  double last = 0.0;
  const Clock::time_point start = Clock::now();
  UdpDatagram d;
  while (reader.next(d)) {
    if (stop_requested()) {
      result.interrupted = true;
      break;
    }
    if (options.port && d.dst_port != *options.port) continue;
    if (!t0) t0 = d.time;
    std::this_thread::sleep_until(departure(start, *t0, d.time, options.rate));  // at once when late
    sender.send(d.payload);
    ++result.datagrams;
    result.bytes += d.payload.size();
    last = d.time;
  }
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (result.datagrams == 0 && !result.interrupted) {
    throw InputError(capture, options.port ? fmt::format("no UDP datagram to port {} in the capture", *options.port)
                                           : std::string("no UDP datagram in the capture"));
  }
  result.capture_seconds = t0 ? last - *t0 : 0.0;
  return result;
}

}  // namespace saloam
