// `saloam replay`: a packet capture's UDP payloads sent to an address at the
// capture's pace (or --rate times it), as the sensor sent them: to try a
// live run (`saloam odom udp://:2368 --sensor vlp16 ...`) without the sensor.
// The sending is sources/capture_replay.hpp's.

#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/error.hpp"
#include "saloam/sources/capture_replay.hpp"

namespace saloam::cli {
namespace {

struct ReplayArgs {
  std::string capture;
  std::string address;
  double rate = 1.0;
  int port = -1;  ///< --port; -1: every datagram
};

int run_replay(const ReplayArgs& args) {
  const UdpAddress to = parse_udp_url(args.address);
  if (to.port == 0) throw InputError(args.address, "port 0: give the port the live run listens on");
  ReplayOptions options;
  options.rate = args.rate;
  if (args.port >= 0) options.port = static_cast<std::uint16_t>(args.port);
  spdlog::info("sending {} to {} at {:g}x its pace", args.capture, to.url(), args.rate);
  const ReplayResult r = replay_capture(args.capture, to, options);
  std::cout << fmt::format("sent {} datagrams ({:.1f} MB) in {:.2f} s ({:.2f} s of capture at {:g}x)\n", r.datagrams,
                           static_cast<double>(r.bytes) / 1e6, r.seconds, r.capture_seconds, args.rate);
  return r.interrupted ? 130 : 0;
}

const CommandRegistration kRegistration{Command{
    "replay", "Send a packet capture's UDP payloads to an address at its recorded pace (to try live runs)", 17,
    [](CLI::App& app) {
      auto args = std::make_shared<ReplayArgs>();
      app.add_option("CAPTURE", args->capture, "A sensor's packet capture (.pcap, .pcapng)")
          ->required()
          ->check(CLI::ExistingFile);
      app.add_option("ADDRESS", args->address, "Where to send: udp://HOST:PORT, e.g. udp://127.0.0.1:2368")->required();
      app.add_option("--rate", args->rate, "The capture's pace times this (10: ten times as fast)")
          ->check(positive_number())
          ->capture_default_str();
      app.add_option("--port", args->port,
                     "Only the datagrams the capture has to this port (7502: an Ouster's lidar packets, not its IMU's)")
          ->check(CLI::Range(0, 65535));
      return [args] { return run_replay(*args); };
    }}};

}  // namespace
}  // namespace saloam::cli
