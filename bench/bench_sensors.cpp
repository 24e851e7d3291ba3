// Packet decoding speed: the real Ouster OS1-128 capture of ../shared
// (RNG15_RFL8_NIR8, 64 packets of 8448 bytes a frame, 1024 x 128 pixels):
// packets to a frame (assembler) and the frame to points (XYZ lookup); and
// one HDL-64E sweep of Velodyne packets (348 packets of 1206 bytes, made in
// memory) to points. The packets are in memory: capture reading not counted.

#include <benchmark/benchmark.h>

#include <filesystem>

#include "saloam/sensors/ouster_frame.hpp"
#include "saloam/sensors/pcap_reader.hpp"
#include "saloam/sensors/velodyne_frame.hpp"

namespace {

using namespace saloam;

const std::filesystem::path kOuster = std::filesystem::path(SALOAM_BENCH_SHARED_DIR) / "data/ouster_pcaps";

struct OusterCapture {
  OusterMetadata metadata = read_ouster_metadata(kOuster / "OS-1-128_v2.3.0_1024x10.json");
  std::vector<std::vector<std::uint8_t>> packets;
  OusterCapture() {
    PcapReader reader(kOuster / "OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
    UdpDatagram d;
    while (reader.next(d)) {
      if (d.dst_port == metadata.udp_port_lidar) packets.push_back(d.payload);
    }
  }
};

void BM_OusterPacketsToFrames(benchmark::State& state) {
  static const OusterCapture capture;
  std::size_t frames = 0;
  for (auto _ : state) {
    OusterFrameAssembler assembler(capture.metadata);
    std::vector<OusterScan> done;
    for (const auto& p : capture.packets) assembler.add(p, done);
    frames += done.size();
    benchmark::DoNotOptimize(done);
  }
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_OusterPacketsToFrames)->Unit(benchmark::kMillisecond);

void BM_OusterFrameToPoints(benchmark::State& state) {
  static const OusterCapture capture;
  OusterFrameAssembler assembler(capture.metadata);
  std::vector<OusterScan> done;
  for (const auto& p : capture.packets) assembler.add(p, done);
  const OusterXyzLut lut(capture.metadata);
  for (auto _ : state) {
    auto cloud = ouster_cloud(done.front(), lut, *done.front().first_valid_timestamp(), 255.0F);
    benchmark::DoNotOptimize(cloud);
  }
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_OusterFrameToPoints)->Unit(benchmark::kMillisecond);

// A stream of sweeps, as a live run or a capture reads them: each iteration
// adds one sweep's 348 packets (the clock going on) to one assembler, which
// hands over the sweep before.
void BM_VelodyneHdl64eSweep(benchmark::State& state) {
  VelodyneCalibration calibration;
  for (int i = 0; i < 64; ++i) {
    VelodyneLaser l;
    l.vert_correction = (2.0 - 0.42 * i) * 3.14159265 / 180.0;
    calibration.lasers.push_back(l);
  }
  constexpr int kPackets = 348;
  const auto sweep_packets = [](int sweep) {
    std::vector<std::vector<std::uint8_t>> packets;
    for (int p = 0; p < kPackets; ++p) {
      std::array<VelodyneFiring, 12> blocks{};
      for (std::size_t b = 0; b < 12; ++b) {
        blocks[b].azimuth = static_cast<std::uint16_t>((18000 + 17 * (6 * p + static_cast<int>(b / 2))) % 36000);
        blocks[b].lower = b % 2 == 1;
        blocks[b].distance.fill(5000);
      }
      const auto time_us = static_cast<std::uint32_t>((288 * (kPackets * sweep + p)) % 3'600'000'000U);
      packets.push_back(encode_velodyne_packet(VelodyneModel::kHdl64e, blocks, time_us));
    }
    return packets;
  };
  std::vector<std::vector<std::vector<std::uint8_t>>> sweeps;
  for (int sweep = 0; sweep < 8; ++sweep) sweeps.push_back(sweep_packets(sweep));
  VelodyneFrameAssembler assembler(VelodyneDecoder(VelodyneModel::kHdl64e, calibration));
  std::vector<VelodyneFrame> done;
  std::size_t sweep = 0;
  for (auto _ : state) {
    // The clock wraps after the 8 sweeps held: a new assembler then (not timed).
    if (sweep == sweeps.size()) {
      state.PauseTiming();
      assembler = VelodyneFrameAssembler(VelodyneDecoder(VelodyneModel::kHdl64e, calibration));
      sweep = 0;
      state.ResumeTiming();
    }
    done.clear();
    for (const auto& p : sweeps[sweep]) assembler.add(p, done);
    ++sweep;
    benchmark::DoNotOptimize(done);
  }
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_VelodyneHdl64eSweep)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
