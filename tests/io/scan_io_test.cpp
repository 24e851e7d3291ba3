#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <span>

#include "saloam/core/error.hpp"
#include "saloam/io/scan_io.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

LabelledCloud make_cloud(std::size_t n) {
  LabelledCloud c;
  c.has_labels = true;
  for (std::size_t i = 0; i < n; ++i) {
    c.push_back({static_cast<float>(i), -static_cast<float>(i) * 0.5f, 1.25f}, 0.01f * static_cast<float>(i),
                static_cast<std::uint16_t>(i % 2 ? 40 : 252), static_cast<std::uint16_t>(i));
  }
  return c;
}

void write_raw(const std::filesystem::path& p, const std::vector<char>& bytes) {
  std::ofstream out(p, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

/// Expects an InputError whose message contains the file name and `fragment`.
template <class F>
void expect_input_error(F&& f, const std::filesystem::path& file, const std::string& fragment) {
  try {
    f();
    FAIL() << "no error; expected: " << fragment;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file.filename().string()), std::string::npos) << what;
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
  }
}

TEST(ScanIo, RoundTripKeepsEveryField) {
  testing::TempDir dir;
  const auto cloud = make_cloud(1000);
  write_scan_bin(dir / "a.bin", cloud);
  write_scan_labels(dir / "a.label", cloud);
  EXPECT_EQ(std::filesystem::file_size(dir / "a.bin"), 16000u);
  EXPECT_EQ(std::filesystem::file_size(dir / "a.label"), 4000u);
  ScanReadStats stats;
  const auto back = read_scan(dir / "a.bin", dir / "a.label", &stats);
  ASSERT_EQ(back.size(), cloud.size());
  EXPECT_TRUE(back.has_labels);
  EXPECT_EQ(stats.points_in_file, 1000u);
  EXPECT_EQ(stats.dropped_nonfinite, 0u);
  EXPECT_EQ(back.points, cloud.points);
  EXPECT_EQ(back.remission, cloud.remission);
  EXPECT_EQ(back.label, cloud.label);
  EXPECT_EQ(back.instance, cloud.instance);
}

TEST(ScanIo, LabelBitLayout) {
  testing::TempDir dir;
  auto cloud = make_cloud(1);
  cloud.label[0] = 252;
  cloud.instance[0] = 7;
  write_scan_labels(dir / "x.label", cloud);
  const auto raw = read_label_file(dir / "x.label");
  ASSERT_EQ(raw.size(), 1u);
  EXPECT_EQ(raw[0], 252u | (7u << 16));
}

TEST(ScanIo, WithoutLabels) {
  testing::TempDir dir;
  write_scan_bin(dir / "a.bin", make_cloud(10));
  const auto back = read_scan(dir / "a.bin");
  EXPECT_FALSE(back.has_labels);
  EXPECT_EQ(back.size(), 10u);
  EXPECT_EQ(back.label[3], 0);
}

TEST(ScanIo, TruncatedBinIsAnError) {
  testing::TempDir dir;
  write_scan_bin(dir / "t.bin", make_cloud(10));
  std::filesystem::resize_file(dir / "t.bin", 16 * 10 - 3);
  expect_input_error([&] { read_scan(dir / "t.bin"); }, dir / "t.bin", "not a multiple of 16");
}

TEST(ScanIo, EmptyAndMissingFilesAreErrors) {
  testing::TempDir dir;
  write_raw(dir / "e.bin", {});
  expect_input_error([&] { read_scan(dir / "e.bin"); }, dir / "e.bin", "empty scan");
  expect_input_error([&] { read_scan(dir / "missing.bin"); }, dir / "missing.bin", "not found");
}

TEST(ScanIo, LabelCountMismatchIsAnError) {
  testing::TempDir dir;
  write_scan_bin(dir / "a.bin", make_cloud(10));
  write_scan_labels(dir / "a.label", make_cloud(9));
  expect_input_error([&] { read_scan(dir / "a.bin", dir / "a.label"); }, dir / "a.label", "9 labels for 10 points");
}

TEST(ScanIo, OddSizedLabelFileIsAnError) {
  testing::TempDir dir;
  write_scan_bin(dir / "a.bin", make_cloud(2));
  write_raw(dir / "a.label", {1, 2, 3, 4, 5, 6});
  expect_input_error([&] { read_scan(dir / "a.bin", dir / "a.label"); }, dir / "a.label", "not a multiple of 4");
}

TEST(ScanIo, NonFinitePointsAreDroppedAndCounted) {
  testing::TempDir dir;
  auto cloud = make_cloud(10);
  cloud.points[2].x() = std::numeric_limits<float>::quiet_NaN();
  cloud.points[5].z() = std::numeric_limits<float>::infinity();
  write_scan_bin(dir / "n.bin", cloud);
  write_scan_labels(dir / "n.label", cloud);
  ScanReadStats stats;
  const auto back = read_scan(dir / "n.bin", dir / "n.label", &stats);
  EXPECT_EQ(stats.dropped_nonfinite, 2u);
  ASSERT_EQ(back.size(), 8u);
  // Labels stay aligned with their points after dropping.
  EXPECT_EQ(back.instance[2], 3);
  EXPECT_EQ(back.instance[4], 6);
  for (const auto& p : back.points) EXPECT_TRUE(p.allFinite());
}

TEST(ScanIo, AbsurdlyDistantPointsAreDroppedAndCounted) {
  testing::TempDir dir;
  auto cloud = make_cloud(6);
  cloud.points[1].y() = 1e30F;   // a broken file, not a measurement
  cloud.points[4].x() = -2e4F;   // beyond any LiDAR's range
  write_scan_bin(dir / "far.bin", cloud);
  ScanReadStats stats;
  const auto back = read_scan(dir / "far.bin", std::nullopt, &stats);
  EXPECT_EQ(stats.dropped_out_of_range, 2u);
  EXPECT_EQ(stats.dropped_nonfinite, 0u);
  ASSERT_EQ(back.size(), 4u);
  for (const auto& p : back.points) EXPECT_LE(p.cwiseAbs().maxCoeff(), kMaxScanCoordinate);
}

TEST(ScanIo, AllNonFiniteIsAnError) {
  testing::TempDir dir;
  auto cloud = make_cloud(3);
  for (auto& p : cloud.points) p.y() = std::numeric_limits<float>::quiet_NaN();
  write_scan_bin(dir / "n.bin", cloud);
  expect_input_error([&] { read_scan(dir / "n.bin"); }, dir / "n.bin", "no finite point");
}

TEST(ScanIo, ReadsRealKittiScan) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto scan = read_scan(testing::shared_file("data/kitti/scans_00/000000.bin"));
  EXPECT_EQ(scan.size(), 124668u);  // the count stated in shared/data/kitti/README.md
  double max_range = 0;
  for (const auto& p : scan.points) max_range = std::max(max_range, static_cast<double>(p.norm()));
  EXPECT_GT(max_range, 50.0);
  EXPECT_LT(max_range, 130.0);
}

}  // namespace
}  // namespace saloam

namespace saloam {
namespace {

std::span<const std::byte> byte_span(const std::vector<char>& bytes) { return std::as_bytes(std::span(bytes)); }

// parse_scan / parse_label_bytes (read_scan's checks on bytes in memory)
// name the file they are given.
TEST(ScanIo, ParsingBytesNamesTheGivenFiles) {
  testing::TempDir dir;
  const auto cloud = make_cloud(3);
  write_scan_bin(dir / "a.bin", cloud);
  write_scan_labels(dir / "a.label", cloud);
  auto bytes_of = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  const auto bin = bytes_of(dir / "a.bin"), labels = bytes_of(dir / "a.label");
  const auto parsed = parse_scan(byte_span(bin), "x.bin", byte_span(labels), "x.label");
  EXPECT_EQ(parsed.size(), 3u);
  EXPECT_EQ(parsed.label, cloud.label);
  EXPECT_EQ(parsed.instance, cloud.instance);

  expect_input_error([&] { (void)parse_scan(byte_span({}), "x.bin"); }, "x.bin", "empty scan");
  const std::vector<char> two_labels(labels.begin(), labels.begin() + 8);
  expect_input_error([&] { (void)parse_scan(byte_span(bin), "x.bin", byte_span(two_labels), "x.label"); },
                     "x.label", "2 labels for 3 points in x.bin");
  expect_input_error([&] { (void)parse_label_bytes(byte_span({'a'}), "y.label"); }, "y.label", "not a multiple of 4");
  // An empty label file is no labels (and no memcpy from a null pointer).
  EXPECT_TRUE(parse_label_bytes(byte_span({}), "y.label").empty());
}

}  // namespace
}  // namespace saloam
