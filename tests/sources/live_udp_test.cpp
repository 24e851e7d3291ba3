// Live UDP sources: the address forms, the queue that drops whole frames,
// the socket's errors, and a simulated Velodyne capture replayed over
// loopback giving the capture's own frames point for point.

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <thread>

#include "saloam/core/error.hpp"
#include "saloam/core/sensor_profile.hpp"
#include "saloam/sim/simulated_source.hpp"
#include "saloam/sensors/pcap_reader.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sources/capture_replay.hpp"
#include "saloam/sources/frame_queue.hpp"
#include "saloam/sources/live_udp_source.hpp"
#include "saloam/sources/open_source.hpp"
#include "saloam/sources/udp_socket.hpp"
#include "saloam/sources/velodyne_capture_writer.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

TEST(UdpUrl, ReadsTheThreeFormsAndNamesAMalformedOne) {
  const UdpAddress any = parse_udp_url("udp://:7502");
  EXPECT_EQ(any.ipv4, 0U);
  EXPECT_EQ(any.port, 7502);
  EXPECT_EQ(parse_udp_url("udp://0.0.0.0:7502").url(), "udp://0.0.0.0:7502");
  const UdpAddress local = parse_udp_url("udp://127.0.0.1:2368");
  EXPECT_EQ(local.ipv4, 0x7F000001U);
  EXPECT_EQ(local.url(), "udp://127.0.0.1:2368");
  EXPECT_TRUE(is_udp_url("udp://:1"));
  EXPECT_FALSE(is_udp_url("seq/udp"));
  for (const std::string bad : {"udp://127.0.0.1", "udp://127.0.0.1:", "udp://127.0.0.1:70000", "udp://:x1",
                                "udp://sensor.local:2368", "udp://[::1]:2368", "udp://1.2.3:2368"}) {
    SCOPED_TRACE(bad);
    const std::string error = testing::input_error_of([&] { (void)parse_udp_url(bad); });
    EXPECT_NE(error.find(bad), std::string::npos) << error;
    EXPECT_NE(error.find("udp://[ADDRESS]:PORT"), std::string::npos) << error;
  }
}

QueuedFrame frame_at(double time) { return {SourceFrame{LabelledCloud{}, time}, std::chrono::steady_clock::now()}; }

/// Whether this process may pass net.core.rmem_max (CAP_NET_ADMIN in /proc/self/status's CapEff).
bool may_force_receive_buffer() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("CapEff:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> 12) & 1U;
  }
  return false;
}

TEST(UdpReceiver, GetsTheBufferAskedForWhereTheProcessMayPassTheKernelsCap) {
  if (!may_force_receive_buffer()) GTEST_SKIP() << "no CAP_NET_ADMIN: the kernel caps the buffer at net.core.rmem_max";
  // 64 MiB, past a default rmem_max (208 KiB; 4 MiB on the development machine); reported twice over.
  const int asked = 64 << 20;
  const UdpReceiver receiver(parse_udp_url("udp://127.0.0.1:0"), asked);
  EXPECT_GE(receiver.buffer_bytes(), asked);
}

TEST(FrameQueue, DropsTheOldestWholeFrameWhenFullAndCountsIt) {
  FrameQueue queue(2);
  for (double t : {0.0, 0.1, 0.2, 0.3, 0.4}) queue.push(frame_at(t));
  EXPECT_EQ(queue.dropped(), 3U);
  EXPECT_EQ(queue.queued(), 2U);
  queue.end("idle");
  // The newest frames remain, in order, and are still served after the end.
  EXPECT_DOUBLE_EQ(queue.pop()->frame.time, 0.3);
  EXPECT_DOUBLE_EQ(queue.pop()->frame.time, 0.4);
  EXPECT_FALSE(queue.pop());
  EXPECT_EQ(queue.ended_by(), "idle");
}

TEST(FrameQueue, APopWaitsForTheReceiver) {
  FrameQueue queue(4);
  std::thread receiver([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    queue.push(frame_at(1.5));
    queue.end("idle");
  });
  const auto first = queue.pop();
  ASSERT_TRUE(first);
  EXPECT_DOUBLE_EQ(first->frame.time, 1.5);
  EXPECT_FALSE(queue.pop());
  receiver.join();
}

SourceOptions vlp16_options(double idle_s) {
  SourceOptions options;
  options.live.sensor = "vlp16";
  options.live.idle_timeout_s = idle_s;
  return options;
}

TEST(LiveUdpSource, SaysWhatIsMissingAndRefusesAPortInUse) {
  const UdpReceiver taken(parse_udp_url("udp://127.0.0.1:0"), 1 << 16);
  const std::string url = taken.address().url();
  std::string error = testing::input_error_of([&] { LiveUdpSource source(url, vlp16_options(1)); });
  EXPECT_NE(error.find(url), std::string::npos) << error;
  EXPECT_NE(error.find("Address already in use"), std::string::npos) << error;
  SourceOptions options = vlp16_options(1);
  options.live.sensor = "auto";
  error = testing::input_error_of([&] { LiveUdpSource source("udp://127.0.0.1:0", options); });
  EXPECT_NE(error.find("--sensor vlp16, hdl32e or hdl64e"), std::string::npos) << error;
  options.live.sensor = "os1-64";
  error = testing::input_error_of([&] { LiveUdpSource source("udp://127.0.0.1:0", options); });
  EXPECT_NE(error.find("--metadata META.json"), std::string::npos) << error;
  options.live.sensor = "hdl64e";  // the HDL-64E has no datasheet angles to fall back on
  error = testing::input_error_of([&] { LiveUdpSource source("udp://127.0.0.1:0", options); });
  EXPECT_NE(error.find("HDL-64E needs its calibration"), std::string::npos) << error;
}

TEST(LiveUdpSource, EndsWhenNoPacketComesWithinTheIdleTimeout) {
  const auto start = std::chrono::steady_clock::now();
  LiveUdpSource source("udp://127.0.0.1:0", vlp16_options(0.2));
  EXPECT_TRUE(source.info().live);
  EXPECT_TRUE(source.info().times.empty());
  EXPECT_FALSE(source.next_frame(0));
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(waited, 0.2);
  EXPECT_LT(waited, 5.0);
  const StreamStats stats = *source.stream_stats();
  EXPECT_EQ(stats.frames_made, 0U);
  EXPECT_NE(stats.ended_by.find("no packet for 0.2 s"), std::string::npos) << stats.ended_by;
}

/// A short simulated VLP-16 drive as a capture (the straight preset), with its calibration beside it.
std::filesystem::path simulate_vlp16_capture(const testing::TempDir& dir, std::size_t frames) {
  SimulationOptions options;
  options.preset = "straight";
  options.end_frame = frames;
  options.sensor = load_sensor_profile(testing::source_dir() / "config" / "sensors" / "vlp16.yaml");
  options.azimuth_steps = options.sensor->simulation.azimuth_steps;
  options.show_progress = false;
  SimulatedSequence sequence(options);
  SimulatedSource source(sequence);
  const LidarModel& lidar = sequence.lidar();
  const auto capture = dir / "vlp16.pcap";
  write_velodyne_capture(source, {lidar.elevation_deg, lidar.azimuth_steps, lidar.sweep_period}, capture);
  return capture;
}

TEST(LiveUdpSource, AReplayedCaptureGivesTheCapturesFramesPointForPoint) {
  testing::TempDir dir;
  const auto capture = simulate_vlp16_capture(dir, 4);
  const auto recorded = open_source(capture, {});
  SourceOptions options = vlp16_options(1.0);
  options.metadata = dir / "vlp16.yaml";  // the calibration the capture is read with
  LiveUdpSource live("udp://127.0.0.1:0", options);
  // 4x the pace: 0.1 s of packets; nothing is dropped, the queue holds them all.
  std::thread sender([&] { (void)replay_capture(capture, live.address(), {.rate = 4.0, .port = std::nullopt}); });
  std::size_t served = 0;
  while (auto frame = live.next_frame(served)) {
    ASSERT_LT(served, recorded->size());
    const LabelledCloud expected = recorded->scan(served);
    EXPECT_EQ(frame->time, recorded->info().times[served]);
    ASSERT_EQ(frame->cloud.size(), expected.size());
    EXPECT_EQ(frame->cloud.points, expected.points);
    EXPECT_EQ(frame->cloud.remission, expected.remission);
    EXPECT_EQ(frame->cloud.ring, expected.ring);
    EXPECT_EQ(frame->cloud.time, expected.time);
    ++served;
  }
  sender.join();
  EXPECT_EQ(served, recorded->size());
  const StreamStats stats = *live.stream_stats();
  EXPECT_EQ(stats.frames_made, recorded->size());
  EXPECT_EQ(stats.frames_served, recorded->size());
  EXPECT_EQ(stats.frames_dropped, 0U);
  EXPECT_EQ(stats.latency_ms.size(), recorded->size());
}

TEST(LiveUdpSource, AFrameThatLostAPacketIsDroppedWhole) {
  testing::TempDir dir;
  const auto capture = simulate_vlp16_capture(dir, 4);
  SourceOptions options = vlp16_options(0.5);
  options.metadata = dir / "vlp16.yaml";
  LiveUdpSource live("udp://127.0.0.1:0", options);
  {
    // Every datagram but one in the second sweep (a VLP-16 sends 75 a sweep), at once: the receive buffer holds them.
    PcapReader reader(capture);
    const UdpSender sender(live.address());
    UdpDatagram d;
    for (std::size_t k = 0; reader.next(d); ++k) {
      if (k != 110) sender.send(d.payload);
    }
  }
  const auto recorded = open_source(capture, {});
  std::vector<double> times;
  while (auto frame = live.next_frame(times.size())) times.push_back(frame->time);
  const StreamStats stats = *live.stream_stats();
  EXPECT_EQ(stats.frames_made, recorded->size());
  EXPECT_EQ(stats.frames_incomplete, 1U);
  EXPECT_EQ(stats.frames_served, recorded->size() - 1);
  EXPECT_NE(stats.packet_counts.find("about 1 missing"), std::string::npos) << stats.packet_counts;
  // The frame left out is the second; the others are the capture's.
  const std::vector<double>& all = recorded->info().times;
  EXPECT_EQ(times, (std::vector<double>{all[0], all[2], all[3]}));
}

}  // namespace
}  // namespace saloam
