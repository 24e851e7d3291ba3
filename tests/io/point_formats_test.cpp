// PCD, PLY and PointCloud2: writing and reading back, hand-written files of
// other tools' layouts, and corrupt files (errors name the file and the problem).
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/binary_file.hpp"
#include "saloam/io/pcd.hpp"
#include "saloam/io/ply.hpp"
#include "saloam/io/point_fields.hpp"
#include "saloam/io/pointcloud2.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

using testing::input_error_of;

/// A small cloud with rings and per-point times.
LabelledCloud sweep_cloud(std::size_t n = 50) {
  LabelledCloud c;
  for (std::size_t i = 0; i < n; ++i) {
    const float a = 0.13f * static_cast<float>(i);
    c.push_back({10.0f * std::cos(a), 10.0f * std::sin(a), -1.73f + 0.01f * static_cast<float>(i)}, 0.01f * static_cast<float>(i));
  }
  c.ring.resize(n);
  c.time.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    c.ring[i] = static_cast<std::uint16_t>(i % 16);
    c.time[i] = -0.05f + 0.1f * static_cast<float>(i) / static_cast<float>(n);
  }
  return c;
}

void expect_same_cloud(const LabelledCloud& a, const LabelledCloud& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.has_rings(), b.has_rings());
  EXPECT_EQ(a.has_times(), b.has_times());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.points[i], b.points[i]) << i;
    ASSERT_EQ(a.remission[i], b.remission[i]) << i;
    if (a.has_rings()) {
      ASSERT_EQ(a.ring[i], b.ring[i]) << i;
    }
    if (a.has_times()) {
      ASSERT_EQ(a.time[i], b.time[i]) << i;
    }
  }
}

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

std::span<const std::byte> bytes_of(const std::string& s) { return std::as_bytes(std::span<const char>(s)); }

TEST(LabelledCloud, OptionalFieldsFollowThePoints) {
  const LabelledCloud source = sweep_cloud(4);
  LabelledCloud copy;
  copy.push_back_from(source, 2);
  copy.push_back_from(source, 3);
  ASSERT_TRUE(copy.has_rings() && copy.has_times());
  EXPECT_EQ(copy.ring[1], source.ring[3]);
  EXPECT_EQ(copy.time[0], source.time[2]);
  copy.push_back({0, 0, 0}, 0.0f);  // a point without ring and time: the cloud has neither
  EXPECT_FALSE(copy.has_rings());
  EXPECT_FALSE(copy.has_times());
  copy.push_back_from(source, 1);
  EXPECT_TRUE(copy.ring.empty() && copy.time.empty());
  copy.clear();
  copy.push_back_from(source, 0);
  EXPECT_TRUE(copy.has_rings());
}

TEST(PointFields, ScalarsRoundTripInBothByteOrders) {
  std::byte buffer[8];
  for (const bool big : {false, true}) {
    for (const ScalarType t : {ScalarType::kInt8, ScalarType::kUint16, ScalarType::kInt32, ScalarType::kUint64,
                               ScalarType::kFloat32, ScalarType::kFloat64}) {
      write_scalar(buffer, t, 100.0, big);
      EXPECT_EQ(read_scalar(buffer, t, big), 100.0) << scalar_name(t);
    }
  }
  write_scalar(buffer, ScalarType::kUint16, 258.0, true);
  EXPECT_EQ(buffer[0], std::byte{1});
  EXPECT_EQ(buffer[1], std::byte{2});
  write_scalar(buffer, ScalarType::kUint8, 1e9, false);  // saturates, no undefined conversion
  EXPECT_EQ(read_scalar(buffer, ScalarType::kUint8, false), 255.0);
}

TEST(Pcd, EveryEncodingRoundTripsWithRingsAndTimes) {
  testing::TempDir dir;
  const LabelledCloud cloud = sweep_cloud();
  for (const auto& [encoding, name] : {std::pair{PcdEncoding::kAscii, "ascii"}, std::pair{PcdEncoding::kBinary, "binary"},
                                      std::pair{PcdEncoding::kBinaryCompressed, "binary_compressed"}}) {
    if (encoding == PcdEncoding::kBinaryCompressed && !pcd_compression_available()) continue;
    const auto file = dir / (std::string(name) + ".pcd");
    write_pcd(file, cloud, encoding);
    const DecodedCloud back = read_pcd(file);
    SCOPED_TRACE(name);
    expect_same_cloud(cloud, back.cloud);
    EXPECT_EQ(back.fields, "x y z intensity ring time");
    EXPECT_EQ(back.points_in_file, cloud.size());
  }
}

// A Velodyne-driver-like layout in another order: padding, a double field
// with 3 elements, uint32 nanosecond times (Ouster's `t`), NaN points.
TEST(Pcd, AnyFieldOrderTypesAndCounts) {
  testing::TempDir dir;
  write_text(dir / "a.pcd",
             "# .PCD v0.7\nVERSION 0.7\nFIELDS t normal ring _ z y x reflectivity intensity\n"
             "SIZE 4 8 1 4 8 4 4 2 2\nTYPE U F U U F F F U U\nCOUNT 1 3 1 1 1 1 1 1 1\n"
             "WIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA ascii\n"
             "1000000 0 0 1 5 0 -1.5 2 1 7 40\n"
             "2000000 0 0 1 6 0 -1.5 nan 1 7 41\n"
             "\n"
             "3000000 0 0 1 7 0 -1.25 3 2 7 42\n"
             "4000000 0 0 1 8 0 -1 4 3 7 43\n");
  const DecodedCloud d = read_pcd(dir / "a.pcd");
  ASSERT_EQ(d.cloud.size(), 3u);  // the NaN point is dropped
  EXPECT_EQ(d.points_in_file, 4u);
  EXPECT_EQ(d.fields, "x y z intensity ring t");
  EXPECT_EQ(d.cloud.points[1], Eigen::Vector3f(2, 3, -1.25f));
  EXPECT_EQ(d.cloud.remission[2], 43.0f);
  EXPECT_EQ(d.cloud.ring[1], 7);
  EXPECT_FLOAT_EQ(d.cloud.time[2], 0.004f);  // nanoseconds to seconds
  EXPECT_FALSE(d.time_reference.has_value());
}

TEST(Pcd, AbsoluteTimesBecomeRelativeToTheScan) {
  testing::TempDir dir;
  write_text(dir / "a.pcd",
             "FIELDS x y z timestamp\nSIZE 4 4 4 8\nTYPE F F F F\nWIDTH 2\nHEIGHT 1\nDATA ascii\n"
             "1 0 0 1600000000.25\n2 0 0 1600000000.30\n");
  const DecodedCloud earliest = read_pcd(dir / "a.pcd");
  EXPECT_NEAR(earliest.cloud.time[1], 0.05, 1e-6);
  EXPECT_DOUBLE_EQ(*earliest.time_reference, 1600000000.25);
  const DecodedCloud stamped = read_pcd(dir / "a.pcd", 1600000000.2);
  EXPECT_NEAR(stamped.cloud.time[0], 0.05, 1e-6);
}

TEST(Pcd, CorruptFilesAreErrorsNamingTheFile) {
  testing::TempDir dir;
  const auto file = dir / "bad.pcd";
  const auto error_of = [&](const std::string& text) {
    write_text(file, text);
    return input_error_of([&] { read_pcd(file); });
  };
  const std::string head = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 1\n";
  EXPECT_NE(error_of(head + "DATA binary\n" + std::string(20, '\0')).find("bad.pcd: truncated: 3 points of 12 bytes"), std::string::npos);
  EXPECT_NE(error_of(head + "DATA ascii\n1 2 3\n4 5\n").find("line 8: 2 values, the header declares 3"), std::string::npos);
  EXPECT_NE(error_of(head + "DATA ascii\n1 2 3\n").find("truncated: 1 of the 3 points"), std::string::npos);
  EXPECT_NE(error_of(head + "DATA ascii\n1 2 x3\n").find("'x3' is not a number"), std::string::npos);
  EXPECT_NE(error_of("FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n").find("no PCD type 'F' of 3 bytes"), std::string::npos);
  EXPECT_NE(error_of("FIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 1\nDATA ascii\n1 2\n").find("no x, y, z fields (fields: x y)"), std::string::npos);
  EXPECT_NE(error_of(head + "POINTS 4\nDATA ascii\n").find("POINTS 4 is not WIDTH 3 x HEIGHT 1"), std::string::npos);
  EXPECT_NE(error_of(head + "DATA lzma\n").find("DATA 'lzma' is not ascii, binary"), std::string::npos);
  EXPECT_NE(error_of("hello\n").find("unknown PCD header key 'hello'"), std::string::npos);
  EXPECT_NE(error_of(head).find("no DATA line"), std::string::npos);
  EXPECT_NE(error_of("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 99999999999\nHEIGHT 99999\nDATA binary\n").find("truncated"), std::string::npos);
  if (!pcd_compression_available()) {  // a build without liblzf says so
    EXPECT_NE(error_of(head + "DATA binary_compressed\n" + std::string(8, '\0')).find("not built into this saloam"), std::string::npos);
  }
  if (pcd_compression_available()) {
    // Sizes that cannot come from the compressed bytes, and corrupt LZF data.
    std::string sizes(8, '\0');
    const std::uint32_t compressed = 4, raw = 36;
    std::memcpy(sizes.data(), &compressed, 4);
    std::memcpy(sizes.data() + 4, &raw, 4);
    EXPECT_NE(error_of(head + "DATA binary_compressed\n" + sizes + "\xff\xff\xff\xff").find("corrupt LZF data"), std::string::npos);
    EXPECT_NE(error_of(head + "DATA binary_compressed\n" + sizes).find("truncated: 4 compressed bytes announced, 0 present"), std::string::npos);
    const std::string big = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 100000000\nHEIGHT 1\nDATA binary_compressed\n";
    const std::uint32_t huge = 1200000000;
    std::memcpy(sizes.data() + 4, &huge, 4);
    EXPECT_NE(error_of(big + sizes + "abcd").find("cannot come from 4 LZF bytes"), std::string::npos);
  }
}

TEST(Ply, EveryEncodingRoundTripsWithRingsAndTimes) {
  testing::TempDir dir;
  const LabelledCloud cloud = sweep_cloud();
  for (const auto encoding : {PlyEncoding::kAscii, PlyEncoding::kBinaryLittleEndian, PlyEncoding::kBinaryBigEndian}) {
    const auto file = dir / fmt::format("{}.ply", static_cast<int>(encoding));
    write_ply_scan(file, cloud, encoding);
    const DecodedCloud back = read_ply_cloud(file);
    SCOPED_TRACE(static_cast<int>(encoding));
    expect_same_cloud(cloud, back.cloud);
    EXPECT_EQ(back.fields, "x y z intensity ring time");
  }
}

TEST(Ply, BigEndianDoublesAfterAnotherElement) {
  testing::TempDir dir;
  std::string text = "ply\r\nformat binary_big_endian 1.0\r\ncomment from elsewhere\r\nelement camera 1\r\nproperty float f\r\n"
                     "element vertex 2\r\nproperty uchar ring\r\nproperty double x\r\nproperty double y\r\nproperty double z\r\n"
                     "property float remission\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n";
  std::vector<std::byte> body(4 + 2 * 29);
  write_scalar(body.data(), ScalarType::kFloat32, 9.0, true);
  for (std::size_t i = 0; i < 2; ++i) {
    std::byte* v = body.data() + 4 + i * 29;
    write_scalar(v, ScalarType::kUint8, 60.0 + static_cast<double>(i), true);
    write_scalar(v + 1, ScalarType::kFloat64, 1.5 + static_cast<double>(i), true);
    write_scalar(v + 9, ScalarType::kFloat64, -2.0, true);
    write_scalar(v + 17, ScalarType::kFloat64, 0.25, true);
    write_scalar(v + 25, ScalarType::kFloat32, 0.5, true);
  }
  text.append(reinterpret_cast<const char*>(body.data()), body.size());
  text += "face data is not read";
  const DecodedCloud d = parse_ply(bytes_of(text), "b.ply");
  ASSERT_EQ(d.cloud.size(), 2u);
  EXPECT_EQ(d.cloud.points[1], Eigen::Vector3f(2.5f, -2.0f, 0.25f));
  EXPECT_EQ(d.cloud.ring[1], 61);
  EXPECT_EQ(d.cloud.remission[0], 0.5f);
  EXPECT_EQ(d.fields, "x y z remission ring");
}

TEST(Ply, MapExportStillReadsBackWithLabels) {
  testing::TempDir dir;
  LabelledCloud cloud = sweep_cloud(10);
  cloud.has_labels = true;
  cloud.label.assign(10, 40);
  write_ply(dir / "map.ply", cloud);
  const LabelledCloud back = read_ply(dir / "map.ply");
  ASSERT_EQ(back.size(), 10u);
  EXPECT_TRUE(back.has_labels);
  EXPECT_EQ(back.label[3], 40);
  EXPECT_FALSE(back.has_rings());
}

TEST(Ply, CorruptFilesAreErrorsNamingTheFile) {
  const auto error_of = [](const std::string& text) { return input_error_of([&] { parse_ply(bytes_of(text), "bad.ply"); }); };
  const std::string head = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  EXPECT_NE(error_of(head + std::string(20, '\0')).find("bad.ply: truncated PLY: 2 vertices of 12 bytes, 20 bytes"), std::string::npos);
  EXPECT_NE(error_of("PLY\n").find("bad.ply: not a PLY file"), std::string::npos);
  EXPECT_NE(error_of("ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float128 x\n").find("header line 4: unknown property type 'float128'"), std::string::npos);
  EXPECT_NE(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\nend_header\n").find("list property"), std::string::npos);
  EXPECT_NE(error_of("ply\nformat ascii 1.0\nelement face 1\nproperty float x\nend_header\n").find("no 'vertex' element"), std::string::npos);
  EXPECT_NE(error_of("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n").find("fewer 'vertex' lines than 2"), std::string::npos);
  EXPECT_NE(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2\n").find("line 8: 2 values"), std::string::npos);
  EXPECT_NE(error_of("ply\nelement vertex 1\n").find("no end_header"), std::string::npos);
  EXPECT_NE(error_of("ply\nformat binary_little_endian 1.0\nelement f 1\nproperty list uchar int i\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n").find("before the vertices has a list property"), std::string::npos);
}

// One set of checks for every format (io/point_checks.hpp, issue #39): points
// at 1e30 and rings that fit no sensor dropped and counted, times beyond a
// sweep clamped and counted, a wrongly stated byte order refused.
TEST(PointChecks, EveryFormatDropsFarPointsAndBadRingsAndClampsTimes) {
  testing::TempDir dir;
  LabelledCloud cloud = sweep_cloud(40);
  cloud.points[3].x() = 1e30f;    // beyond kMaxScanCoordinate
  cloud.points[4].z() = -2e4f;    // too
  cloud.ring[5] = 5000;           // no sensor has 5000 lasers
  cloud.time[6] = -100.0f;        // 100 s before the scan's timestamp
  cloud.time[7] = 50.0f;          // 50 s after it (below kAbsoluteTimeThreshold: not an absolute time)
  const auto check = [](const DecodedCloud& d, const std::string& what) {
    SCOPED_TRACE(what);
    EXPECT_EQ(d.points_in_file, 40u);
    ASSERT_EQ(d.cloud.size(), 37u);
    EXPECT_EQ(d.checks.out_of_range, 2u);
    EXPECT_EQ(d.checks.bad_ring, 1u);
    EXPECT_EQ(d.checks.time_before_sweep, 1u);
    EXPECT_EQ(d.checks.time_after_sweep, 1u);
    for (std::size_t i = 0; i < d.cloud.size(); ++i) {
      EXPECT_LE(d.cloud.points[i].cwiseAbs().maxCoeff(), kMaxScanCoordinate) << i;
      EXPECT_LT(d.cloud.ring[i], kMaxRings) << i;
      EXPECT_LE(std::abs(d.cloud.time[i]), kMaxSweepSeconds) << i;
    }
    EXPECT_EQ(d.cloud.time[3], -static_cast<float>(kMaxSweepSeconds));  // point 6, after 3 dropped
    EXPECT_EQ(d.cloud.time[4], static_cast<float>(kMaxSweepSeconds));
  };
  for (const auto encoding : {PcdEncoding::kAscii, PcdEncoding::kBinary}) {
    const auto file = dir / fmt::format("c{}.pcd", static_cast<int>(encoding));
    write_pcd(file, cloud, encoding);
    check(read_pcd(file), file.string());
  }
  for (const auto encoding : {PlyEncoding::kAscii, PlyEncoding::kBinaryLittleEndian, PlyEncoding::kBinaryBigEndian}) {
    const auto file = dir / fmt::format("c{}.ply", static_cast<int>(encoding));
    write_ply_scan(file, cloud, encoding);
    check(read_ply_cloud(file), file.string());
  }
  const auto bytes = serialize_pointcloud2(cloud, 1317042145.125, "velodyne", 7);
  check(parse_pointcloud2(bytes, "x.bag", "topic /points, message 0").decoded, "PointCloud2");
  // Nothing left: an error that says why.
  LabelledCloud far = sweep_cloud(3);
  for (auto& p : far.points) p.y() = 1e30f;
  write_pcd(dir / "far.pcd", far, PcdEncoding::kBinary);
  EXPECT_NE(input_error_of([&] { (void)read_pcd(dir / "far.pcd"); }).find("no point with finite coordinates within 10000 m"),
            std::string::npos);
}

TEST(PointChecks, AWronglyStatedByteOrderIsRefused) {
  testing::TempDir dir;
  const LabelledCloud cloud = sweep_cloud(200);
  write_ply_scan(dir / "le.ply", cloud, PlyEncoding::kBinaryLittleEndian);
  std::ifstream in(dir / "le.ply", std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find("binary_little_endian");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, std::strlen("binary_little_endian"), "binary_big_endian");  // the same length: the data stays
  const std::string error = input_error_of([&] { (void)parse_ply(bytes_of(text), "swapped.ply"); });
  EXPECT_NE(error.find("swapped.ply: the data is little-endian although the header says big-endian"), std::string::npos)
      << error;
  // A cloud of mostly missing (NaN) returns stated rightly is no such case.
  LabelledCloud sparse = sweep_cloud(200);
  for (std::size_t i = 0; i < 150; ++i) sparse.points[i].x() = std::numeric_limits<float>::quiet_NaN();
  write_ply_scan(dir / "sparse.ply", sparse, PlyEncoding::kBinaryBigEndian);
  EXPECT_EQ(read_ply_cloud(dir / "sparse.ply").cloud.size(), 50u);
  // PointCloud2: is_bigendian wrongly set (the byte after the fields).
  auto bytes = serialize_pointcloud2(cloud, 5.0, "velodyne");
  const std::size_t fields_end = 4 + 8 + 4 + 8 + 8 + 4 + (4 + 1 + 4 + 1 + 4) * 3 + (4 + 9 + 4 + 1 + 4) +
                                 (4 + 4 + 4 + 1 + 4) + (4 + 4 + 4 + 1 + 4);
  ASSERT_EQ(bytes[fields_end], std::byte{0});
  bytes[fields_end] = std::byte{1};
  EXPECT_NE(input_error_of([&] { (void)parse_pointcloud2(bytes, "x.bag", "message 0"); })
                .find("x.bag: message 0: the data is little-endian although the header says big-endian"),
            std::string::npos);
}

TEST(PointCloud2, SerialisedMessagesRoundTrip) {
  const LabelledCloud cloud = sweep_cloud();
  const auto bytes = serialize_pointcloud2(cloud, 1317042145.125, "velodyne", 7);
  const PointCloud2Scan scan = parse_pointcloud2(bytes, "x.bag", "topic /points, message 0");
  EXPECT_EQ(scan.header.seq, 7u);
  EXPECT_NEAR(scan.header.stamp, 1317042145.125, 1e-6);
  EXPECT_EQ(scan.header.frame_id, "velodyne");
  EXPECT_EQ(scan.width, cloud.size());
  expect_same_cloud(cloud, scan.decoded.cloud);
  EXPECT_EQ(parse_ros_header(bytes, "x.bag", "m").frame_id, "velodyne");
}

TEST(PointCloud2, InconsistentMessagesAreErrorsNamingTheBag) {
  const LabelledCloud cloud = sweep_cloud(4);
  const auto good = serialize_pointcloud2(cloud, 5.0, "velodyne");
  const auto error_of = [](std::vector<std::byte> bytes) {
    return input_error_of([&] { parse_pointcloud2(bytes, "x.bag", "topic /points, message 3"); });
  };
  auto cut = good;
  cut.resize(good.size() - 10);
  EXPECT_NE(error_of(cut).find("x.bag: topic /points, message 3: cut off in data"), std::string::npos);
  // point_step (after the fields) smaller than the fields: 16 bytes of x y z intensity.
  const std::size_t fields_end = 4 + 8 + 4 + 8 + 8 + 4 + (4 + 1 + 4 + 1 + 4) * 3 + (4 + 9 + 4 + 1 + 4) + (4 + 4 + 4 + 1 + 4) + (4 + 4 + 4 + 1 + 4);
  auto small_step = good;
  const std::uint32_t step = 8;
  std::memcpy(small_step.data() + fields_end + 1, &step, 4);
  EXPECT_NE(error_of(small_step).find("does not fit in point_step 8"), std::string::npos);
  auto short_row = good;
  const std::uint32_t row = 20;
  std::memcpy(short_row.data() + fields_end + 5, &row, 4);
  EXPECT_NE(error_of(short_row).find("row_step 20 is shorter than width 4"), std::string::npos);
}

}  // namespace
}  // namespace saloam
