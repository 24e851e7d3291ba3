// ROS 2 recordings (issue 40): rosbag2 .db3 folders and .mcap files written
// by sequence_writer.hpp and read back by Ros2BagSource with the scans,
// rings, per-point times and stamps they were given, in every MCAP chunk
// compression and both CDR byte orders; the topic picked as in ROS 1 bags;
// an MCAP file cut short read up to its last whole message; corrupt files
// refused with the file named.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/db3.hpp"
#include "saloam/io/mcap.hpp"
#include "saloam/io/pointcloud2.hpp"
#include "saloam/io/rosbag2_metadata.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sources/open_source.hpp"
#include "saloam/sources/ros2_bag_source.hpp"
#include "saloam/sources/sequence_writer.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::input_error_of;

/// A short simulated SemanticKITTI sequence (16 beams, coarse azimuth: cheap).
const fs::path& simulated_sequence() {
  static testing::TempDir dir("saloam_ros2_sim");
  static const bool written = [] {
    SimulationOptions options;
    options.preset = "straight";
    options.end_frame = 6;
    options.beams = 16;
    options.azimuth_steps = 600;
    options.show_progress = false;
    simulate_sequence(options, dir / "seq");
    return true;
  }();
  (void)written;
  static const fs::path seq = dir / "seq";
  return seq;
}

/// Rings and per-point times on every scan, as a driver's clouds have.
class WithPointFields final : public FrameSource {
 public:
  explicit WithPointFields(FrameSource& inner) : inner_(inner) {}
  [[nodiscard]] const SourceInfo& info() const override { return inner_.info(); }
  LabelledCloud scan(std::size_t i) override {
    LabelledCloud c = inner_.scan(i);
    c.ring.resize(c.size());
    c.time.resize(c.size());
    for (std::size_t k = 0; k < c.size(); ++k) {
      c.ring[k] = static_cast<std::uint16_t>(k % 16);
      c.time[k] = 0.1f * static_cast<float>(k) / static_cast<float>(c.size());
    }
    return c;
  }

 private:
  FrameSource& inner_;
};

SourceOptions on_topic(const std::string& topic) {
  SourceOptions o;
  o.topic = topic;
  return o;
}

void expect_same_scans(FrameSource& a, FrameSource& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a.info().times[i], b.info().times[i], 1e-9) << i;  // whole ns in the message
    const LabelledCloud ca = a.scan(i), cb = b.scan(i);
    ASSERT_EQ(ca.points, cb.points) << i;
    ASSERT_EQ(ca.remission, cb.remission) << i;
    ASSERT_EQ(ca.ring, cb.ring) << i;
    ASSERT_EQ(ca.time, cb.time) << i;
  }
}

fs::path write_as(FrameSource& source, const fs::path& out, ScanFormat format,
                  McapCompression compression = McapCompression::kZstd, bool big_endian = false,
                  std::size_t chunk_bytes = 1u << 20) {
  SequenceWriteOptions o;
  o.format = format;
  o.mcap_compression = compression;
  o.cdr_big_endian = big_endian;
  o.mcap_chunk_bytes = chunk_bytes;
  write_scan_sequence(source, out, o);
  return out;
}

std::string bytes_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void write_bytes(const fs::path& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

TEST(Ros2Bags, Db3FolderRoundTripsScansRingsTimesAndStamps) {
  auto seq = open_reader(simulated_sequence(), {});
  WithPointFields fields(*seq);
  testing::TempDir dir;
  write_as(fields, dir / "bag", ScanFormat::kRosbag2);
  EXPECT_EQ(format_name(ScanFormat::kRosbag2), "rosbag2");
  EXPECT_EQ(format_name(ScanFormat::kMcap), "mcap");
  EXPECT_EQ(detect_scan_format(dir / "bag"), ScanFormat::kRosbag2);
  EXPECT_EQ(detect_scan_format(dir / "bag" / "bag_0.db3"), ScanFormat::kRosbag2);
  auto back = open_reader(dir / "bag", {});
  EXPECT_EQ(back->info().format, "rosbag2");
  EXPECT_EQ(back->info().point_fields, "x y z intensity ring time");
  expect_same_scans(fields, *back);
  const Rosbag2Metadata metadata = read_rosbag2_metadata(dir / "bag");
  EXPECT_EQ(metadata.storage, "sqlite3");
  ASSERT_EQ(metadata.files.size(), 1u);
  EXPECT_EQ(metadata.files[0].filename(), "bag_0.db3");
  // A folder named with a trailing separator names its file alike.
  write_as(fields, (dir / "slash").string() + "/", ScanFormat::kRosbag2);
  EXPECT_TRUE(fs::exists(dir / "slash" / "slash_0.db3"));
}

// rosbag2 folders with MCAP storage, and bags split into several files
// (rosbag2's --max-bag-size): the files named by metadata.yaml, read one
// after the other.
TEST(Ros2Bags, FoldersOfMcapFilesAndSplitBagsAreReadFileByFile) {
  auto seq = open_reader(simulated_sequence(), {});
  testing::TempDir dir;
  fs::create_directories(dir / "mcap_bag");
  write_as(*seq, dir / "mcap_bag" / "mcap_bag_0.mcap", ScanFormat::kMcap);
  write_bytes(dir / "mcap_bag" / "metadata.yaml",
              "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  relative_file_paths:\n"
              "    - mcap_bag_0.mcap\n  compression_format: \"\"\n");
  auto mcap_bag = open_reader(dir / "mcap_bag", {});
  EXPECT_EQ(mcap_bag->info().format, "rosbag2");
  expect_same_scans(*seq, *mcap_bag);

  fs::create_directories(dir / "split");
  for (std::size_t part = 0; part < 2; ++part) {
    Db3Writer db(dir / "split" / fmt::format("split_{}.db3", part));
    const auto topic = db.add_topic("/points", std::string(kRos2PointCloud2Type));
    for (std::size_t i = 3 * part; i < 3 * part + 3; ++i) {
      const double t = seq->info().times[i];
      db.write(topic, std::llround(t * 1e9), serialize_pointcloud2_cdr(seq->scan(i), t, "velodyne"));
    }
    db.close("");
  }
  write_bytes(dir / "split" / "metadata.yaml",
              "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n  relative_file_paths: [split_0.db3, split_1.db3]\n");
  auto split = open_reader(dir / "split", {});
  expect_same_scans(*seq, *split);
  // Listed in the wrong order, the second file's stamps do not follow the first's.
  write_bytes(dir / "split" / "metadata.yaml",
              "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n  relative_file_paths: [split_1.db3, split_0.db3]\n");
  EXPECT_NE(input_error_of([&] { open_reader(dir / "split", {}); }).find("split_0.db3: topic /points, message 3: header stamp"),
            std::string::npos);
}

TEST(Ros2Bags, McapRoundTripsInEveryCompressionAndByteOrder) {
  auto seq = open_reader(simulated_sequence(), {});
  WithPointFields fields(*seq);
  testing::TempDir dir;
  struct Case {
    const char* name;
    McapCompression compression;
    bool big_endian;
  };
  for (const Case& c : {Case{"zstd.mcap", McapCompression::kZstd, false}, Case{"lz4.mcap", McapCompression::kLz4, false},
                        Case{"none.mcap", McapCompression::kNone, false}, Case{"big.mcap", McapCompression::kZstd, true}}) {
    SCOPED_TRACE(c.name);
    write_as(fields, dir / c.name, ScanFormat::kMcap, c.compression, c.big_endian, 200000);
    EXPECT_EQ(detect_scan_format(dir / c.name), ScanFormat::kMcap);
    auto back = open_reader(dir / c.name, {});
    EXPECT_EQ(back->info().format, "mcap");
    expect_same_scans(fields, *back);
    McapReader reader(dir / c.name);
    EXPECT_TRUE(reader.indexed());
    EXPECT_TRUE(reader.notes().empty());
  }
  // No chunks at all: messages straight in the data section, read from the start.
  write_as(fields, dir / "flat.mcap", ScanFormat::kMcap, McapCompression::kNone, false, 0);
  EXPECT_FALSE(McapReader(dir / "flat.mcap").indexed());
  EXPECT_TRUE(McapReader(dir / "flat.mcap").notes().empty());
  auto flat = open_reader(dir / "flat.mcap", {});
  expect_same_scans(fields, *flat);
  // Big-endian CDR in a rosbag2 folder too.
  write_as(fields, dir / "big_bag", ScanFormat::kRosbag2, McapCompression::kZstd, true);
  auto big = open_reader(dir / "big_bag", {});
  expect_same_scans(fields, *big);
}

TEST(Ros2Bags, CdrMessagesOfEitherByteOrderDecodeAlike) {
  auto seq = open_reader(simulated_sequence(), {});
  const LabelledCloud cloud = seq->scan(1);
  const auto little = serialize_pointcloud2_cdr(cloud, 12.25, "lidar", false);
  const auto big = serialize_pointcloud2_cdr(cloud, 12.25, "lidar", true);
  EXPECT_EQ(little[1], std::byte{1});
  EXPECT_EQ(big[1], std::byte{0});
  const PointCloud2Scan a = parse_pointcloud2_cdr(little, "x.mcap", "m");
  const PointCloud2Scan b = parse_pointcloud2_cdr(big, "x.mcap", "m");
  EXPECT_EQ(a.header.stamp, 12.25);
  EXPECT_EQ(b.header.frame_id, "lidar");
  EXPECT_EQ(a.decoded.cloud.points, cloud.points);
  EXPECT_EQ(b.decoded.cloud.points, cloud.points);
  EXPECT_EQ(parse_ros2_header(big, "x.mcap", "m").stamp, 12.25);
  // Cut off anywhere: an error naming the file and the message, never a crash.
  for (const std::size_t n : {std::size_t{2}, std::size_t{11}, std::size_t{40}, little.size() / 2, little.size() - 2}) {
    const std::string error = input_error_of([&] { parse_pointcloud2_cdr(std::span(little).first(n), "x.mcap", "topic /points, message 3"); });
    EXPECT_NE(error.find("x.mcap: topic /points, message 3: "), std::string::npos) << n << " " << error;
  }
  auto xcdr2 = little;
  xcdr2[1] = std::byte{7};
  EXPECT_NE(input_error_of([&] { parse_pointcloud2_cdr(xcdr2, "x.mcap", "m"); }).find("only plain CDR"), std::string::npos);
}

TEST(Ros2Bags, TopicIsPickedAsInRos1Bags) {
  auto seq = open_reader(simulated_sequence(), {});
  testing::TempDir dir;
  const LabelledCloud cloud = seq->scan(0);
  {
    McapWriter mcap(dir / "two.mcap", McapCompression::kLz4);
    const auto schema = mcap.add_schema(std::string(kRos2PointCloud2Type), "ros2msg", kRos2PointCloud2Definition);
    const auto front = mcap.add_channel("/front", schema, "cdr");
    const auto rear = mcap.add_channel("/rear", schema, "cdr");
    const auto imu_schema = mcap.add_schema("sensor_msgs/msg/Imu", "ros2msg", "");
    const auto imu = mcap.add_channel("/imu", imu_schema, "cdr");
    for (int i = 0; i < 3; ++i) {
      const auto t = static_cast<std::uint64_t>(i) * 100000000u;
      mcap.write(front, t, serialize_pointcloud2_cdr(cloud, 0.1 * i, "front"));
      mcap.write(rear, t, serialize_pointcloud2_cdr(cloud, 0.1 * i, "rear"));
      mcap.write(imu, t, std::vector<std::byte>(8));
    }
  }
  EXPECT_NE(input_error_of([&] { open_reader(dir / "two.mcap", {}); })
                .find("two.mcap: 2 sensor_msgs/msg/PointCloud2 topics: pick one with --topic: /front "
                      "(sensor_msgs/msg/PointCloud2, 3 messages); /rear (sensor_msgs/msg/PointCloud2, 3 messages)"),
            std::string::npos);
  EXPECT_EQ(open_reader(dir / "two.mcap", on_topic("/rear"))->size(), 3u);
  EXPECT_NE(input_error_of([&] { open_reader(dir / "two.mcap", on_topic("/imu")); })
                .find("topic '/imu' holds sensor_msgs/msg/Imu, not sensor_msgs/msg/PointCloud2"),
            std::string::npos);
  EXPECT_NE(input_error_of([&] { open_reader(dir / "two.mcap", on_topic("/lidar")); }).find("no topic '/lidar'; the bag holds: /front"),
            std::string::npos);
  {
    Db3Writer db(dir / "two.db3");
    const auto a = db.add_topic("/a", std::string(kRos2PointCloud2Type));
    const auto b = db.add_topic("/b", std::string(kRos2PointCloud2Type));
    for (int i = 0; i < 2; ++i) {
      db.write(a, i, serialize_pointcloud2_cdr(cloud, 1.0 + i, "a"));
      db.write(b, i, serialize_pointcloud2_cdr(cloud, 1.0 + i, "b"));
    }
    db.close("");
  }
  EXPECT_NE(input_error_of([&] { open_reader(dir / "two.db3", {}); }).find("2 sensor_msgs/msg/PointCloud2 topics: pick one with --topic: /a"),
            std::string::npos);
  EXPECT_EQ(open_reader(dir / "two.db3", on_topic("/b"))->info().times, (std::vector<double>{1.0, 2.0}));
}

// A recording cut short (the recorder killed, the disk full) has no summary
// and no footer, and its last chunk is cut off: it is read from the start,
// up to the last whole message, with a note; compressed chunks are
// decompressed as far as their bytes go.
TEST(Ros2Bags, McapCutShortIsReadUpToItsLastWholeMessage) {
  auto seq = open_reader(simulated_sequence(), {});
  testing::TempDir dir;
  for (const auto compression : {McapCompression::kZstd, McapCompression::kLz4, McapCompression::kNone}) {
    const fs::path whole = dir / fmt::format("whole_{}.mcap", static_cast<int>(compression));
    write_as(*seq, whole, ScanFormat::kMcap, compression, false, 1u << 22);  // one chunk for all six scans
    const std::string bytes = bytes_of(whole);
    const fs::path cut = dir / fmt::format("cut_{}.mcap", static_cast<int>(compression));
    // Cut inside the last message of the only chunk.
    write_bytes(cut, bytes.substr(0, bytes.size() * 93 / 100));
    McapReader reader(cut);
    EXPECT_FALSE(reader.indexed());
    ASSERT_EQ(reader.notes().size(), 1u);
    EXPECT_NE(reader.notes()[0].find("ends without its footer"), std::string::npos);
    auto back = open_reader(cut, {});
    EXPECT_GE(back->size(), 4u) << static_cast<int>(compression);
    EXPECT_LT(back->size(), 6u);
    for (std::size_t i = 0; i < back->size(); ++i) ASSERT_EQ(back->scan(i).points, seq->scan(i).points) << i;
  }
  // Several chunks, cut in the last: every earlier chunk whole.
  const fs::path chunked = dir / "chunked.mcap";
  write_as(*seq, chunked, ScanFormat::kMcap, McapCompression::kZstd, false, 1);  // a chunk per message
  const std::string bytes = bytes_of(chunked);
  write_bytes(dir / "chunked_cut.mcap", bytes.substr(0, bytes.size() - 2000));
  auto back = open_reader(dir / "chunked_cut.mcap", {});
  EXPECT_EQ(back->size(), 5u);
  EXPECT_EQ(back->info().notes.back().find("the MCAP file ends without its footer"), 0u);
}

TEST(Ros2Bags, CorruptFilesAreRefusedNamingTheFile) {
  auto seq = open_reader(simulated_sequence(), {});
  testing::TempDir dir;
  write_as(*seq, dir / "good.mcap", ScanFormat::kMcap, McapCompression::kZstd, false, 200000);
  const std::string good = bytes_of(dir / "good.mcap");
  const auto error_of = [&](const std::string& bytes) {
    write_bytes(dir / "bad.mcap", bytes);
    return input_error_of([&] {
      auto source = open_reader(dir / "bad.mcap", {});
      for (std::size_t i = 0; i < source->size(); ++i) source->scan(i);
    });
  };
  EXPECT_NE(error_of("\x89MCAP0\r\n").find("bad.mcap: not an MCAP file"), std::string::npos);
  EXPECT_NE(error_of(std::string(good).replace(0, 4, "PK\x03\x04")).find("bad.mcap: not an MCAP file (no MCAP magic)"), std::string::npos);
  // A byte flipped inside the first chunk's compressed records.
  std::string flipped = good;
  flipped[200] = static_cast<char>(flipped[200] ^ 0x5A);
  EXPECT_NE(error_of(flipped).find("bad.mcap: corrupt MCAP file: chunk at byte 35: "), std::string::npos) << error_of(flipped);
  // A summary whose chunk index points past the file: refused, not followed.
  const std::size_t footer = good.size() - 8 - 29;
  std::uint64_t summary_start;
  std::memcpy(&summary_start, good.data() + footer + 9, 8);
  std::string moved = good;
  const std::uint64_t far = good.size() + 1000;
  std::memcpy(moved.data() + footer + 9, &far, 8);
  EXPECT_NE(error_of(moved).find("bad.mcap: corrupt MCAP file: footer at byte"), std::string::npos) << error_of(moved);
  // A huge length in the first record after the header.
  std::string huge = good;
  const std::uint64_t length = 1ull << 62;
  const std::size_t first_after_header = 8 + 9 + (4 + 4) + (4 + 6);
  std::memcpy(huge.data() + first_after_header + 1, &length, 8);
  EXPECT_NE(error_of(huge).find("bad.mcap: "), std::string::npos);

  write_bytes(dir / "bad.db3", std::string(4096, 'x'));
  EXPECT_NE(input_error_of([&] { open_reader(dir / "bad.db3", {}); }).find("bad.db3: not a rosbag2 database: file is not a database"),
            std::string::npos);
  fs::create_directories(dir / "folder");
  write_bytes(dir / "folder" / "metadata.yaml", "rosbag2_bagfile_information:\n  storage_identifier: bag_v2\n");
  EXPECT_NE(input_error_of([&] { open_reader(dir / "folder", {}); }).find("metadata.yaml: storage 'bag_v2': saloam reads sqlite3 and mcap"),
            std::string::npos);
  write_bytes(dir / "folder" / "metadata.yaml", "rosbag2_bagfile_information:\n  relative_file_paths: [../../etc/passwd]\n");
  EXPECT_NE(input_error_of([&] { open_reader(dir / "folder", {}); }).find("is not a file name inside the bag"), std::string::npos);
  write_bytes(dir / "folder" / "metadata.yaml",
              "rosbag2_bagfile_information:\n  compression_format: zstd\n  compression_mode: FILE\n");
  EXPECT_NE(input_error_of([&] { open_reader(dir / "folder", {}); }).find("compressed by rosbag2 (zstd, FILE mode)"), std::string::npos);
}

}  // namespace
}  // namespace saloam
