// Captures written and read again: UDP payloads by port, IPv4 fragments put
// back together, positions to come back to, corrupt files refused.

#include <gtest/gtest.h>

#include <fstream>
#include <numeric>

#include "saloam/core/error.hpp"
#include "saloam/sensors/pcap_reader.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

std::vector<std::uint8_t> bytes(std::size_t n, std::uint8_t first) {
  std::vector<std::uint8_t> out(n);
  std::iota(out.begin(), out.end(), first);
  return out;
}

TEST(PcapReader, ReadsBackWhatWasWrittenFragmentsIncluded) {
  testing::TempDir dir;
  const auto file = dir / "c.pcap";
  {
    PcapWriter writer(file);
    writer.write(10.25, bytes(1206, 0), 2368);
    writer.write(10.5, bytes(16640, 3), 7502);  // 12 fragments over a 1500-byte MTU
    writer.write(11.0, bytes(48, 9), 7503);
    writer.close();
  }
  EXPECT_TRUE(has_pcap_magic(file));
  PcapReader reader(file);
  UdpDatagram d;
  std::vector<std::int64_t> offsets;
  ASSERT_TRUE(reader.next(d));
  EXPECT_EQ(d.dst_port, 2368);
  EXPECT_EQ(d.payload, bytes(1206, 0));
  EXPECT_DOUBLE_EQ(d.time, 10.25);
  offsets.push_back(d.offset);
  ASSERT_TRUE(reader.next(d));
  EXPECT_EQ(d.dst_port, 7502);
  EXPECT_EQ(d.payload, bytes(16640, 3));
  offsets.push_back(d.offset);
  ASSERT_TRUE(reader.next(d));
  EXPECT_EQ(d.payload.size(), 48U);
  EXPECT_FALSE(reader.next(d));
  EXPECT_EQ(reader.counts().datagrams, 3U);
  EXPECT_EQ(reader.counts().fragments, 12U);
  EXPECT_EQ(reader.counts().incomplete, 0U);
  // Back to the fragmented datagram.
  reader.seek(offsets[1]);
  ASSERT_TRUE(reader.next(d));
  EXPECT_EQ(d.payload, bytes(16640, 3));
}

TEST(PcapReader, FragmentsInAnyOrderAndUnfinishedOnesBounded) {
  Ipv4Reassembler r;
  const auto data = bytes(3000, 0);
  const std::span<const std::uint8_t> all(data);
  Ipv4Reassembler::Fragment last{1, 2, 7, 17, 2000, false, all.subspan(2000), 0};
  Ipv4Reassembler::Fragment first{1, 2, 7, 17, 0, true, all.first(1000), 0};
  Ipv4Reassembler::Fragment middle{1, 2, 7, 17, 1000, true, all.subspan(1000, 1000), 0};
  EXPECT_FALSE(r.add(last));
  EXPECT_FALSE(r.add(first));
  const auto whole = r.add(middle);
  ASSERT_TRUE(whole);
  EXPECT_EQ(whole->bytes, data);
  for (std::uint16_t id = 0; id < 200; ++id) EXPECT_FALSE(r.add({1, 2, id, 17, 0, true, all.first(8), 0}));
  EXPECT_EQ(r.dropped(), 200U - kMaxPendingDatagrams);
  EXPECT_FALSE(r.add({1, 2, 9, 17, 65000, false, all.first(1000), 0}));  // beyond 65535 bytes
}

TEST(PcapReader, CorruptCapturesNameTheFile) {
  testing::TempDir dir;
  const auto text = dir / "text.pcap";
  std::ofstream(text) << "not a capture at all";
  EXPECT_NE(testing::input_error_of([&] { PcapReader r(text); }).find("text.pcap"), std::string::npos);

  const auto file = dir / "c.pcap";
  {
    PcapWriter writer(file);
    writer.write(1.0, bytes(1206, 0), 2368);
    writer.write(2.0, bytes(1206, 0), 2368);
  }
  // Cut in the middle of the second record.
  std::filesystem::resize_file(file, std::filesystem::file_size(file) - 100);
  PcapReader reader(file);
  UdpDatagram d;
  EXPECT_TRUE(reader.next(d));
  const std::string error = testing::input_error_of([&] { reader.next(d); });
  EXPECT_NE(error.find("c.pcap"), std::string::npos);
  EXPECT_NE(error.find("corrupt capture record"), std::string::npos);
}

}  // namespace
}  // namespace saloam
