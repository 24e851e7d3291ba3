#include <gtest/gtest.h>

#include <sys/stat.h>

#include <fstream>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/lie.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::input_error_of;

TEST(Errors, TextIsPlainAndShortWhateverTheInputHeld) {
  const InputError nul("poses.txt", std::string("line 2: '1 0\0secret' is not a number", 36));
  EXPECT_STREQ(nul.what(), "poses.txt: line 2: '1 0\\x00secret' is not a number");
  const InputError huge("big.txt", "line 1: '" + std::string(10'000'000, 'x') + "' is not a number");
  EXPECT_LT(std::string(huge.what()).size(), 700u);
  EXPECT_NE(std::string(huge.what()).find("... (9999"), std::string::npos) << huge.what();
  EXPECT_STREQ(ConfigError("a\tb\x1b[31m").what(), "a\tb\\x1b[31m");
}

TEST(Files, Utf8AndHexForPathsInJson) {
  EXPECT_TRUE(is_valid_utf8("/tmp/plain"));
  EXPECT_TRUE(is_valid_utf8("/tmp/caf\xc3\xa9/\xe2\x82\xac/\xf0\x9f\x98\x80"));  // é, €, an emoji
  EXPECT_FALSE(is_valid_utf8("bad\xff\xfename"));
  EXPECT_FALSE(is_valid_utf8("cut\xc3"));            // a sequence cut short
  EXPECT_FALSE(is_valid_utf8("\xc0\xaf"));          // overlong '/'
  EXPECT_FALSE(is_valid_utf8("\xed\xa0\x80"));      // a surrogate
  EXPECT_FALSE(is_valid_utf8("\xf4\x90\x80\x80"));  // beyond U+10FFFF
  const std::string bytes("a\xff\x00/z", 5);
  EXPECT_EQ(to_hex(bytes), "61ff002f7a");
  EXPECT_EQ(from_hex(to_hex(bytes)), bytes);
  EXPECT_FALSE(from_hex("6"));
  EXPECT_FALSE(from_hex("zz"));
  EXPECT_FALSE(from_hex("6A"));  // to_hex writes lower case only
}

TEST(Files, RequireFileNamesWhatIsWrong) {
  testing::TempDir dir;
  std::ofstream(dir / "a.txt") << "x";
  EXPECT_NO_THROW(require_file(dir / "a.txt"));
  EXPECT_EQ(input_error_of([&] { require_file(dir / "none.txt", "pose file"); }),
            (dir / "none.txt").string() + ": pose file not found");
  fs::create_directories(dir / "folder.txt");
  EXPECT_EQ(input_error_of([&] { require_file(dir / "folder.txt"); }),
            (dir / "folder.txt").string() + ": is a directory, not a file");
}

TEST(Files, ReadFileReadsOnlyRegularFilesWithinTheLimit) {
  testing::TempDir dir;
  std::ofstream(dir / "a.txt") << "12345";
  EXPECT_EQ(read_file(dir / "a.txt", 5), "12345");
  EXPECT_EQ(input_error_of([&] { read_file(dir / "a.txt", 4, "pose file"); }),
            (dir / "a.txt").string() + ": is 5 bytes, more than a pose file may have (4 bytes)");
  EXPECT_EQ(input_error_of([&] { read_file(dir / "none.txt", 10, "pose file"); }),
            (dir / "none.txt").string() + ": pose file not found");
  fs::create_directories(dir / "poses.txt");
  EXPECT_EQ(input_error_of([&] { read_file(dir / "poses.txt", 10, "pose file"); }),
            (dir / "poses.txt").string() + ": is a directory, not a pose file");
  // A link to /dev/zero is never read without end, a FIFO never waited on.
  fs::create_symlink("/dev/zero", dir / "zero.yaml");
  EXPECT_EQ(input_error_of([&] { read_file(dir / "zero.yaml", 1 << 20, "configuration file"); }),
            (dir / "zero.yaml").string() + ": is not a regular file (expected a configuration file)");
  ASSERT_EQ(::mkfifo((dir / "fifo.yaml").c_str(), 0600), 0);
  EXPECT_EQ(input_error_of([&] { read_file(dir / "fifo.yaml", 1 << 20, "configuration file"); }),
            (dir / "fifo.yaml").string() + ": is not a regular file (expected a configuration file)");
  EXPECT_TRUE(path_taken(dir / "fifo.yaml"));
  fs::create_symlink(dir / "nowhere", dir / "dangling");
  EXPECT_TRUE(path_taken(dir / "dangling"));
  EXPECT_FALSE(path_taken(dir / "nowhere"));
}

TEST(Files, CreateFolderReportsThePathAndReason) {
  testing::TempDir dir;
  create_folder(dir / "a/b/c");
  EXPECT_TRUE(fs::is_directory(dir / "a/b/c"));
  create_parent_folder(dir / "d/e/file.txt");
  EXPECT_TRUE(fs::is_directory(dir / "d/e"));
  std::ofstream(dir / "plain") << "x";
  const std::string msg = input_error_of([&] { create_folder(dir / "plain/sub"); });
  EXPECT_EQ(msg.rfind((dir / "plain/sub").string() + ": cannot create folder: ", 0), 0u) << msg;
  try {
    fs::create_directories(dir / "plain/sub");
    FAIL() << "no filesystem_error";
  } catch (const fs::filesystem_error& e) {
    const std::string text = describe(e);
    EXPECT_EQ(text.find("filesystem error"), std::string::npos) << text;
    EXPECT_NE(text.find((dir / "plain").string()), std::string::npos) << text;
  }
}

TEST(Lie, OrthonormalityErrorSeparatesRoundingFromScale) {
  EXPECT_EQ(orthonormality_error(Eigen::Matrix3d::Identity()), 0.0);
  EXPECT_LT(orthonormality_error(so3_exp(Eigen::Vector3d(0.3, -1.0, 2.0))), 1e-12);
  EXPECT_GT(orthonormality_error(Eigen::Vector3d(2.0, 0.5, 1.0).asDiagonal()), 1.0);
  Eigen::Matrix3d rounded = Eigen::Matrix3d::Identity();
  rounded(0, 1) = 1e-4;
  EXPECT_LT(orthonormality_error(rounded), kRotationTolerance);
}

}  // namespace
}  // namespace saloam
