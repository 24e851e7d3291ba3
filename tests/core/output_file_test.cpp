// Output files are complete or absent; an output folder serves one run and
// holds only that run's results.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "saloam/core/error.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/output_folder.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::input_error_of;
using testing::TempDir;

std::string contents(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(CheckedFileStream, AFullDeviceIsReportedWithTheFileName) {
  const int fd = ::open("/dev/full", O_WRONLY | O_CLOEXEC);
  if (fd < 0) GTEST_SKIP() << "no /dev/full";
  CheckedFileStream out(fd, "result.txt");
  for (int i = 0; i < 20000; ++i) out.stream() << "1.000000 2.000000 3.000000\n";
  const std::string message = input_error_of([&] { out.close(); });
  EXPECT_EQ(message, "result.txt: cannot write: no space left on the device");
}

TEST(AtomicFile, TheFinalNameAppearsOnlyWhenCommitted) {
  TempDir dir;
  const fs::path file = dir / "sub/poses.txt";
  {
    AtomicFile out(file);
    out.stream() << "line 1\n";
    out.flush();
    EXPECT_FALSE(fs::exists(file));
    EXPECT_TRUE(is_partial_output_name(out.temporary().filename().string())) << out.temporary();
    EXPECT_EQ(contents(out.temporary()), "line 1\n");
    out.commit();
  }
  EXPECT_EQ(contents(file), "line 1\n");
  EXPECT_EQ(names_in(dir / "sub"), std::vector<std::string>{"poses.txt"});
}

TEST(AtomicFile, AnUncommittedFileLeavesTheEarlierOneUntouched) {
  TempDir dir;
  const fs::path file = dir / "map.ply";
  std::ofstream(file) << "earlier";
  {
    AtomicFile out(file);
    out.stream() << "half of a new map";
  }
  EXPECT_EQ(contents(file), "earlier");
  EXPECT_EQ(names_in(dir.path()), std::vector<std::string>{"map.ply"});
}

TEST(AtomicFile, AFailedRenameNamesTheFileAndRemovesTheTemporary) {
  TempDir dir;
  fs::create_directories(dir / "summary.json/inside");  // a non-empty folder cannot be replaced by a file
  AtomicFile out(dir / "summary.json");
  out.stream() << "{}";
  const std::string message = input_error_of([&] { out.commit(); });
  EXPECT_EQ(message.rfind((dir / "summary.json").string() + ": cannot put the finished file in place: ", 0), 0u)
      << message;
  EXPECT_FALSE(fs::exists(out.temporary()));
}

TEST(AtomicFile, PartialNamesAreRecognised) {
  EXPECT_TRUE(is_partial_output_name("poses.txt.partial-123.0"));
  EXPECT_FALSE(is_partial_output_name("poses.txt"));
  EXPECT_FALSE(is_partial_output_name("poses.partial-x.1"));
  EXPECT_FALSE(is_partial_output_name(".partial-1.2"));
}

TEST(OutputFolder, ASecondRunOnTheFolderStopsAtOnceNamingTheFirst) {
  TempDir dir;
  const OutputFolder first(dir / "out", "slam");
  const std::string message = input_error_of([&] { OutputFolder second(dir / "out", "odom"); });
  EXPECT_NE(message.find((dir / "out").string() + ": another saloam run (slam, process " +
                         std::to_string(::getpid()) + ") is writing this folder"),
            std::string::npos)
      << message;
}

TEST(OutputFolder, AFolderReachedThroughALinkAfterAMissingFolderIsTheSameFolder) {
  TempDir dir;
  const OutputFolder first(dir / "out", "slam");
  fs::create_directory_symlink(dir / "out", dir / "link");
  const std::string message = input_error_of([&] { OutputFolder second(dir / "new" / ".." / "link", "odom"); });
  EXPECT_NE(message.find("slam"), std::string::npos) << message;
}

TEST(OutputFolder, AnotherProcessHoldingTheLockIsRespected) {
  TempDir dir;
  { const OutputFolder earlier(dir.path(), "slam"); }
  const int fd = ::open((dir / ".saloam-run").c_str(), O_RDWR | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);  // an open file description of its own, as another process has
  EXPECT_NE(input_error_of([&] { OutputFolder folder(dir.path(), "slam"); }).find("another saloam run"),
            std::string::npos);
  ::close(fd);
  EXPECT_NO_THROW(OutputFolder folder(dir.path(), "slam"));
}

TEST(OutputFolder, ARunRemovesWhatTheEarlierRunWroteAndRecordsItsOwnFiles) {
  TempDir dir;
  {
    OutputFolder earlier(dir.path(), "slam");
    write_file_atomically(dir / "map.ply", "old map");
    write_file_atomically(dir / "graphs/000001.json", "{}");
    earlier.finish("complete");
  }
  std::ofstream(dir / "notes.txt") << "the user's";
  std::ofstream(dir / "poses.txt.partial-99.3") << "a killed run's";
  std::ofstream(dir / "timing.json") << "a run of an earlier version";
  {
    OutputFolder run(dir.path(), "odom", {"timing.json", "poses.txt"});
    EXPECT_EQ(names_in(dir.path()), (std::vector<std::string>{".saloam-run", "graphs", "notes.txt"}));
    write_file_atomically(dir / "poses.txt", "new");
    EXPECT_EQ(run.files(), std::vector<std::string>{"poses.txt"});
    EXPECT_TRUE(run.wrote("poses.txt"));
    run.finish("interrupted");
  }
  EXPECT_EQ(recorded_outputs(dir.path()), std::vector<std::string>{"poses.txt"});
  const std::string record = contents(dir / ".saloam-run");
  EXPECT_NE(record.find("command odom\n"), std::string::npos) << record;
  EXPECT_NE(record.find("end interrupted\n"), std::string::npos) << record;
}

TEST(OutputFolder, ARunThatDoesNotFinishIsRecordedAsFailed) {
  TempDir dir;
  { const OutputFolder run(dir.path(), "slam"); }
  EXPECT_NE(contents(dir / ".saloam-run").find("end failed\n"), std::string::npos);
}

TEST(OutputFolder, JoiningKeepsTheRunsFilesAndAddsItsOwn) {
  TempDir dir;
  {
    OutputFolder run(dir.path(), "slam");
    write_file_atomically(dir / "poses.txt", "x");
    run.finish("complete");
  }
  {
    const OutputFolder view = OutputFolder::join(dir.path(), "view");
    write_file_atomically(dir / "view.html", "<html>");
  }
  EXPECT_EQ(recorded_outputs(dir.path()), (std::vector<std::string>{"poses.txt", "view.html"}));
}

TEST(OutputFolder, RecordsListOnlyNamesInsideTheFolder) {
  TempDir dir;
  std::ofstream(dir / "keep.txt") << "x";
  fs::create_directories(dir / "out");
  std::ofstream(dir / "out/.saloam-run") << "saloam-run 1\nfile ../keep.txt\nfile /etc/hostname\n";
  const OutputFolder run(dir / "out", "slam");
  EXPECT_TRUE(fs::exists(dir / "keep.txt"));
}

}  // namespace
}  // namespace saloam
