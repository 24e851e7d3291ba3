// Every reader brings remission to 0..1 (io/intensity_scale.hpp): a scan
// stored as 0..255 reads as its 0..1 twin, integer fields by their type,
// one range for the whole source (decided on its first scan), and
// SourceOptions::intensity_scale (--intensity-scale) overrides the guess.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include <fmt/format.h>

#include "saloam/io/intensity_scale.hpp"
#include "saloam/io/pcd.hpp"
#include "saloam/io/ply.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/sources/open_source.hpp"
#include "saloam/sources/rosbag_source.hpp"
#include "saloam/sources/sequence_summary.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

/// A scan whose remission holds whole numbers 0..`top` (as a 0..255 file
/// stores them); `unit` divides them by `top` (its 0..1 twin, computed as a
/// reader divides).
LabelledCloud scan_with_intensities(float top, bool unit, std::size_t n = 600) {
  LabelledCloud c;
  for (std::size_t i = 0; i < n; ++i) {
    const float a = 0.01F * static_cast<float>(i);
    const float value = static_cast<float>((i * 37) % (static_cast<std::size_t>(top) + 1));
    c.push_back({8.0F * std::cos(a), 8.0F * std::sin(a), -1.5F + 0.001F * static_cast<float>(i)},
                unit ? value / top : value);
  }
  return c;
}

void expect_same_remission(const LabelledCloud& a, const LabelledCloud& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.points[i], b.points[i]) << i;
    ASSERT_EQ(a.remission[i], b.remission[i]) << i;
  }
}

/// What the source's intensity note says (after "intensity: ").
std::string intensity_of(const FrameSource& source) {
  const auto note = intensity_note(source.info().notes);
  return note ? note->substr(std::string("intensity: ").size()) : "no intensity note";
}

bool starts_with(const std::string& text, const std::string& head) { return text.rfind(head, 0) == 0; }

SourceOptions with_scale(float divisor) {
  SourceOptions o;
  o.intensity_scale = divisor;
  return o;
}

TEST(IntensitySources, SemanticKittiBinOf0To255ReadsAsItsUnitTwin) {
  testing::TempDir dir;
  const SequenceWriter bytes(dir / "bytes"), unit(dir / "unit");
  bytes.write_scan(0, scan_with_intensities(255.0F, false));
  unit.write_scan(0, scan_with_intensities(255.0F, true));
  // The second scan is dark (values 0 and 1 only): it keeps the sequence's
  // range, where a guess of its own would take it for 0..1.
  bytes.write_scan(1, scan_with_intensities(1.0F, false));
  LabelledCloud dark_unit = scan_with_intensities(1.0F, false);
  for (float& r : dark_unit.remission) r /= 255.0F;
  unit.write_scan(1, dark_unit);

  auto a = open_reader(dir / "bytes", {});
  auto b = open_reader(dir / "unit", {});
  EXPECT_TRUE(starts_with(intensity_of(*a), "0-255, divided by 255 (detected: float32 field, peak 254 in the first scan"))
      << intensity_of(*a);
  EXPECT_TRUE(starts_with(intensity_of(*b), "0-1, kept (detected")) << intensity_of(*b);
  for (std::size_t i = 0; i < 2; ++i) expect_same_remission(a->scan(i), b->scan(i));
  // A frame range keeps the range of the whole sequence.
  SourceOptions second;
  second.frames = FrameRange::parse("1:2");
  expect_same_remission(open_source(dir / "bytes", second)->scan(0), b->scan(1));
  // What `saloam info` lists.
  const auto notes = summarize(*a, 1).notes;
  EXPECT_NE(std::find(notes.begin(), notes.end(), "intensity: " + intensity_of(*a)), notes.end());

  // The given scale wins over the values.
  auto kept = open_reader(dir / "bytes", with_scale(1.0F));
  EXPECT_EQ(intensity_of(*kept), "0-1, kept (as given (--intensity-scale 1))");
  EXPECT_EQ(kept->scan(0).remission, read_scan(dir / "bytes/velodyne/000000.bin").remission);
}

TEST(IntensitySources, KittiRawDriveOf0To255ReadsAsItsUnitTwin) {
  testing::TempDir dir;
  for (const auto& [name, unit] : {std::pair{"bytes", false}, std::pair{"unit", true}}) {
    const fs::path data = dir / name / "velodyne_points" / "data";
    fs::create_directories(data);
    write_scan_bin(data / "0000000000.bin", scan_with_intensities(255.0F, unit));
    write_scan_bin(data / "0000000001.bin", scan_with_intensities(255.0F, unit, 300));
  }
  auto a = open_reader(dir / "bytes", {});
  auto b = open_reader(dir / "unit", {});
  EXPECT_EQ(a->info().format, "kitti-raw");
  EXPECT_TRUE(starts_with(intensity_of(*a), "0-255, divided by 255")) << intensity_of(*a);
  for (std::size_t i = 0; i < 2; ++i) expect_same_remission(a->scan(i), b->scan(i));
  EXPECT_EQ(open_reader(dir / "bytes", with_scale(65535.0F))->scan(0).remission[1], 37.0F / 65535.0F);
}

TEST(IntensitySources, PcdAndPlyOf0To255ReadAsTheirUnitTwins) {
  testing::TempDir dir;
  for (const auto& [name, unit] : {std::pair{"bytes", false}, std::pair{"unit", true}}) {
    fs::create_directories(dir / name / "pcd");
    fs::create_directories(dir / name / "ply");
    write_pcd(dir / name / "pcd" / "000000.pcd", scan_with_intensities(255.0F, unit), PcdEncoding::kBinary);
    write_ply_scan(dir / name / "ply" / "000000.ply", scan_with_intensities(255.0F, unit), PlyEncoding::kAscii);
  }
  for (const char* format : {"pcd", "ply"}) {
    auto a = open_reader(dir / "bytes" / format, {});
    auto b = open_reader(dir / "unit" / format, {});
    EXPECT_TRUE(starts_with(intensity_of(*a), "0-255, divided by 255")) << format << ": " << intensity_of(*a);
    expect_same_remission(a->scan(0), b->scan(0));
  }
}

TEST(IntensitySources, IntegerFieldsAreScaledByTheirType) {
  testing::TempDir dir;
  // uint8 intensity, as PCL's PointXYZI exports of Velodyne drivers hold it.
  std::ofstream(dir / "u8.pcd") << "VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 1\nTYPE F F F U\nCOUNT 1 1 1 1\n"
                                   "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n"
                                   "1 0 0 0\n2 0 0 1\n3 0 0 51\n";
  auto u8 = open_reader(dir / "u8.pcd", {});
  EXPECT_EQ(intensity_of(*u8), "0-255, divided by 255 (uint8 field)");
  const LabelledCloud c8 = u8->scan(0);
  EXPECT_EQ(c8.remission, (std::vector<float>{0.0F, 1.0F / 255.0F, 51.0F / 255.0F}));

  // uint16, Ouster's signal: 0..65535.
  const auto ply16 = [&](const std::string& name, int top) {
    std::ofstream out(dir / name);
    out << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
           "property ushort intensity\nend_header\n"
        << "1 0 0 0\n2 0 0 7\n3 0 0 " << top << "\n";
  };
  ply16("u16.ply", 4000);
  auto u16 = open_reader(dir / "u16.ply", {});
  EXPECT_EQ(intensity_of(*u16), "0-65535, divided by 65535 (uint16 field)");
  EXPECT_EQ(u16->scan(0).remission[2], 4000.0F / 65535.0F);
  // A uint16 field whose values stay within 0..255 holds 8-bit values.
  ply16("u16_8bit.ply", 200);
  auto u16_8bit = open_reader(dir / "u16_8bit.ply", {});
  EXPECT_TRUE(starts_with(intensity_of(*u16_8bit), "0-255, divided by 255 (uint16 field, its values within 0-255"))
      << intensity_of(*u16_8bit);
  EXPECT_EQ(u16_8bit->scan(0).remission[2], 200.0F / 255.0F);
  // The given scale wins over the type.
  EXPECT_EQ(open_reader(dir / "u8.pcd", with_scale(1.0F))->scan(0).remission[2], 51.0F);

  // A file without an intensity field reads remission 0, and says so.
  std::ofstream(dir / "xyz.pcd") << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                                    "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n";
  EXPECT_EQ(intensity_of(*open_reader(dir / "xyz.pcd", {})), "0-1, kept (no intensity field: remission 0)");
}

TEST(IntensitySources, BagOf0To255ReadsAsItsUnitTwin) {
  if (!rosbag_available()) GTEST_SKIP() << "built without rosbag_storage";
  testing::TempDir dir;
  for (const auto& [name, unit] : {std::pair{"bytes.bag", false}, std::pair{"unit.bag", true}}) {
    PointCloud2BagWriter writer(dir / name, "/points", "velodyne");
    writer.write(scan_with_intensities(255.0F, unit), 10.0);
    writer.write(scan_with_intensities(255.0F, unit, 200), 10.1);
  }
  auto a = open_reader(dir / "bytes.bag", {});
  auto b = open_reader(dir / "unit.bag", {});
  EXPECT_TRUE(starts_with(intensity_of(*a), "0-255, divided by 255")) << intensity_of(*a);
  for (std::size_t i = 0; i < 2; ++i) expect_same_remission(a->scan(i), b->scan(i));
}

}  // namespace
}  // namespace saloam
