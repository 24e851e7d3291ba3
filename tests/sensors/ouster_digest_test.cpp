// The Ouster decoder against the manufacturer's own digests: the captures of
// ../shared/data/ouster_pcaps come with *_digest.json files that ouster-sdk
// wrote (python/src/ouster/sdk/core/_digest.py): an MD5 per packet field over
// every lidar packet (column headers as uint64 timestamp, uint32 encoder
// count, uint16 measurement id, uint32 status, uint16 frame id; pixel fields
// as pixels x columns arrays of the field's integer type), and per frame the
// frame id, the column timestamps (uint64), statuses (uint64), measurement
// ids (uint16) and each pixel field as a staggered height x width image.
// Every hash in the files must come out the same, but ENCODER_COUNT of
// frames, which the SDK itself no longer checks (deprecated, not kept in
// its frames).

#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "md5.hpp"
#include "saloam/sensors/ouster_frame.hpp"
#include "saloam/sensors/pcap_reader.hpp"
#include "sensors/ouster_pcaps.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

using Hashes = std::map<std::string, std::string>;
using testing::Md5;

std::vector<std::vector<std::uint8_t>> lidar_packets(const std::filesystem::path& pcap, const OusterMetadata& m) {
  PcapReader reader(pcap);
  std::vector<std::vector<std::uint8_t>> packets;
  UdpDatagram d;
  while (reader.next(d)) {
    if (d.dst_port == m.udp_port_lidar) packets.push_back(d.payload);
  }
  return packets;
}

/// `value`'s low `bytes` bytes, little-endian, into the hash.
void add(Md5& md5, std::uint64_t value, std::size_t bytes) {
  std::array<std::uint8_t, 8> b{};
  for (std::size_t i = 0; i < bytes; ++i) b[i] = static_cast<std::uint8_t>(value >> (8 * i));
  md5.update({b.data(), bytes});
}

Hashes packet_hashes(const OusterPacketFormat& format, const std::vector<std::vector<std::uint8_t>>& packets) {
  std::map<std::string, Md5> md5;
  for (const auto& packet : packets) {
    const std::span<const std::uint8_t> p(packet);
    for (std::uint32_t c = 0; c < format.columns_per_packet(); ++c) add(md5["TIMESTAMP"], format.col_timestamp(p, c), 8);
    for (std::uint32_t c = 0; c < format.columns_per_packet(); ++c) add(md5["ENCODER_COUNT"], format.col_encoder(p, c), 4);
    for (std::uint32_t c = 0; c < format.columns_per_packet(); ++c) {
      add(md5["MEASUREMENT_ID"], format.col_measurement_id(p, c), 2);
    }
    for (std::uint32_t c = 0; c < format.columns_per_packet(); ++c) add(md5["STATUS"], format.col_status(p, c), 4);
    for (std::uint32_t c = 0; c < format.columns_per_packet(); ++c) add(md5["FRAME_ID"], format.col_frame_id(p, c), 2);
    for (const auto& f : format.fields()) {
      Md5& h = md5[std::string(ouster_field_name(f.field))];
      for (std::uint32_t px = 0; px < format.pixels_per_column(); ++px) {
        for (std::uint32_t c = 0; c < format.columns_per_packet(); ++c) add(h, format.pixel(p, c, px, f), f.bytes);
      }
    }
  }
  Hashes out;
  for (auto& [name, h] : md5) out[name] = h.hex();
  return out;
}

Hashes frame_hashes(const OusterScan& scan, const OusterPacketFormat& format) {
  Hashes out;
  out["FRAME_ID"] = std::to_string(scan.frame_id);
  Md5 timestamp, status, id;
  for (std::uint32_t u = 0; u < scan.width; ++u) {
    add(timestamp, scan.timestamp[u], 8);
    add(status, scan.status[u], 8);
    add(id, scan.measurement_id[u], 2);
  }
  out["TIMESTAMP"] = timestamp.hex();
  out["STATUS"] = status.hex();
  out["MEASUREMENT_ID"] = id.hex();
  for (const auto& [f, values] : scan.fields) {
    Md5 h;
    const std::size_t bytes = format.layout(f)->bytes;
    for (std::uint32_t v : values) add(h, v, bytes);
    out[std::string(ouster_field_name(f))] = h.hex();
  }
  return out;
}

std::vector<OusterScan> frames_of(const std::vector<std::vector<std::uint8_t>>& packets, const OusterMetadata& m) {
  OusterFrameAssembler assembler(m);
  std::vector<OusterScan> frames;
  for (const auto& p : packets) assembler.add(p, frames);
  if (auto last = assembler.finish()) frames.push_back(std::move(*last));
  return frames;
}

/// Compares every hash of `expected` (a digest file's object) with `actual`.
void expect_hashes(const nlohmann::json& expected, const Hashes& actual, const std::string& what,
                   std::size_t* compared) {
  for (const auto& [name, value] : expected.items()) {
    if (what != "packets" && name == "ENCODER_COUNT") continue;  // the SDK's check skips it too
    const auto it = actual.find(name);
    ASSERT_NE(it, actual.end()) << what << ": no field " << name;
    EXPECT_EQ(it->second, value.get<std::string>()) << what << " field " << name;
    ++*compared;
  }
}

nlohmann::json read_json(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return nlohmann::json::parse(text.str());
}

TEST(OusterDigest, ReproducesTheManufacturersDigests) {
  SALOAM_REQUIRE_SHARED_DATA();
  SALOAM_REQUIRE_OUSTER_PCAPS();
  const std::vector<std::string> captures{"OS-0-32-U1_v2.2.0_1024x10", "OS-0-128-U1_v2.3.0_1024x10",
                                          "OS-1-32-G_v2.1.1_1024x10"};
  for (const auto& name : captures) {
    SCOPED_TRACE(name);
    const auto folder = testing::shared_file("data/ouster_pcaps");
    const OusterMetadata m = read_ouster_metadata(folder / (name + ".json"));
    const auto digest = read_json(folder / (name + "_digest.json"));
    const auto packets = lidar_packets(folder / (name + ".pcap"), m);
    ASSERT_FALSE(packets.empty());
    const OusterPacketFormat format(m);
    std::size_t compared = 0;
    expect_hashes(digest["packet_hash"], packet_hashes(format, packets), "packets", &compared);
    const auto frames = frames_of(packets, m);
    const auto& scans = digest["scans"];
    ASSERT_EQ(frames.size(), scans.size());
    for (std::size_t i = 0; i < frames.size(); ++i) {
      expect_hashes(scans[i], frame_hashes(frames[i], format), "frame " + std::to_string(i), &compared);
    }
    EXPECT_GE(compared, 15U);
  }
}

}  // namespace
}  // namespace saloam
