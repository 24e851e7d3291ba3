// `cmake --install` puts the program and its data under a prefix, and the
// installed program finds its data there (not in the source tree).

#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::quoted;
using testing::run_command;

TEST(InstallCli, InstalledProgramFindsItsConfigurationsUnderThePrefix) {
  testing::TempDir prefix("saloam_install");
  std::string output;
  ASSERT_EQ(run_command(fmt::format("{} --install {} --prefix {}", quoted(SALOAM_TEST_CMAKE_COMMAND),
                                    quoted(SALOAM_TEST_BUILD_DIR), quoted(prefix.path())),
                        &output),
            0)
      << output;
  const fs::path program = prefix / "bin" / "saloam";
  ASSERT_TRUE(fs::exists(program)) << output;
  EXPECT_TRUE(fs::exists(prefix / "share/saloam/config/saloam.yaml"));
  EXPECT_TRUE(fs::exists(prefix / "share/saloam/config/real_kitti.yaml"));

  // A shipped configuration by name: real_kitti sets the pose instant to mid-sweep.
  ASSERT_EQ(run_command("env -u SALOAM_DATA_DIR " + quoted(program) + " config --config real_kitti", &output), 0) << output;
  EXPECT_NE(output.find("pose_time_in_sweep: 0.05"), std::string::npos) << output;
  // It is the installed copy that is read: remove it and the name is unknown.
  fs::remove(prefix / "share/saloam/config/real_kitti.yaml");
  EXPECT_NE(run_command("env -u SALOAM_DATA_DIR " + quoted(program) + " config --config real_kitti", &output), 0);
  EXPECT_NE(output.find((prefix / "share/saloam/config").string()), std::string::npos) << output;

  // The trainer, when built (libtorch), installs beside saloam, where `saloam sgpr-train` finds it.
  if (fs::exists(fs::path(SALOAM_TEST_BUILD_DIR) / "saloam-sgpr-train")) {
    EXPECT_TRUE(fs::is_regular_file(prefix / "bin" / "saloam-sgpr-train"));
    ASSERT_EQ(run_command(quoted(program) + " sgpr-train --help", &output), 0) << output;
    EXPECT_NE(output.find("--pairs-per-epoch"), std::string::npos) << output;
  }

  // With libtorch, the segmentation plugin and the shipped model install
  // too, and the installed program segments with them (not the build tree's).
  if (fs::exists(fs::path(SALOAM_TEST_BUILD_DIR) / "libsaloam_segment_torch.so")) {
    EXPECT_TRUE(fs::is_regular_file(prefix / "share/saloam/models/segmenter/saloam.yaml"));
    const fs::path seq = prefix / "seq";
    ASSERT_EQ(run_command(quoted(program) + " -q simulate --preset urban-loop --frames 0:2 --beams 16 --out " + quoted(seq),
                          &output),
              0)
        << output;
    ASSERT_EQ(run_command("env -u SALOAM_DATA_DIR " + quoted(program) + " segment " + quoted(seq) + " --out " +
                              quoted(prefix / "labels"),
                          &output),
              0)
        << output;
    EXPECT_NE(output.find((prefix / "share/saloam/models/segmenter/saloam.yaml").string()), std::string::npos) << output;
  }
}

}  // namespace
}  // namespace saloam
