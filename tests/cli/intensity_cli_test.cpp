// End-to-end: the intensity range a source is read with (io/intensity_scale.hpp)
// is said by `saloam info` and in the run's log, --intensity-scale sets it,
// and (with libtorch) a 0..255 .bin sequence gets the labels of its 0..1 twin.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "saloam/io/scan_io.hpp"
#include "cli/cli_fixture.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using namespace testing;

/// Copies the SemanticKITTI folder `from` to `to` with every scan's remission
/// as a 0..255 file stores it (round(255 r)) or, `unit`, as that divided by
/// 255: two twins that must read alike.
void write_twin(const fs::path& from, const fs::path& to, bool unit) {
  fs::create_directories(to);
  for (const auto& entry : fs::directory_iterator(from)) {
    if (entry.is_regular_file()) fs::copy_file(entry.path(), to / entry.path().filename());
  }
  fs::create_directories(to / "velodyne");
  for (const auto& entry : fs::directory_iterator(from / "velodyne")) {
    LabelledCloud cloud = read_scan(entry.path());
    for (float& r : cloud.remission) {
      const float bytes = std::round(255.0F * r);
      r = unit ? bytes / 255.0F : bytes;
    }
    write_scan_bin(to / "velodyne" / entry.path().filename(), cloud);
  }
}

TEST(IntensityCli, InfoAndTheLogSayTheRangeAndTheOptionSetsIt) {
  TempDir dir;
  write_street_sequence(dir / "unit", 2);
  write_twin(dir / "unit", dir / "bytes", false);
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd("info ") + quoted(dir / "bytes"), &output), 0) << output;
  expect_has(output, "  - intensity: 0-255, divided by 255 (detected: float32 field, peak 77 in the first scan");
  expect_has(output, "[info] intensity: 0-255, divided by 255");  // the log line
  ASSERT_EQ(run_command(saloam_cmd("info ") + quoted(dir / "unit"), &output), 0) << output;
  expect_has(output, "  - intensity: 0-1, kept (detected: float32 field, peak 0.3 in the first scan");
  ASSERT_EQ(run_command(saloam_cmd("info --intensity-scale 1 ") + quoted(dir / "bytes"), &output), 0) << output;
  expect_has(output, "  - intensity: 0-1, kept (as given (--intensity-scale 1))");
  EXPECT_NE(run_command(saloam_cmd("info --intensity-scale 100 ") + quoted(dir / "bytes"), &output), 0);
  expect_has(output, "--intensity-scale");
}

#ifdef SALOAM_HAVE_TORCH

// The shipped model labels a 0..255 .bin sequence exactly as its 0..1 twin.
TEST(IntensityCli, SegmentLabelsA0To255SequenceAsItsUnitTwin) {
  TempDir dir;
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd("-q simulate --preset urban-loop --frames 0:3 --beams 16 --out ") +
                            quoted(dir / "seq"),
                        &output),
            0)
      << output;
  write_twin(dir / "seq", dir / "bytes", false);
  write_twin(dir / "seq", dir / "unit", true);
  for (const char* name : {"bytes", "unit"}) {
    ASSERT_EQ(run_command(saloam_cmd("-q segment ") + quoted(dir / name) + " --no-score --out " +
                              quoted(dir / (std::string("pred_") + name)),
                          &output),
              0)
        << output;
  }
  for (int i = 0; i < 3; ++i) {
    const std::string file = "00000" + std::to_string(i) + ".label";
    const auto bytes = read_label_file(dir / "pred_bytes" / file);
    EXPECT_EQ(bytes.size(), read_scan(dir / "bytes" / "velodyne" / ("00000" + std::to_string(i) + ".bin")).size());
    EXPECT_EQ(bytes, read_label_file(dir / "pred_unit" / file)) << file;
  }
}

#endif

}  // namespace
}  // namespace saloam
