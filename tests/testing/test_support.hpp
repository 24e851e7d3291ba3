#pragma once
// Helpers for the test suites.

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "saloam/core/error.hpp"

namespace saloam::testing {

/// The development data folder: $SALOAM_SHARED_DIR when set (the `saloam`
/// program reads the same variable), else ../shared beside the repository
/// (CMake's SALOAM_SHARED_DIR). A clone on its own has no such folder.
std::filesystem::path shared_dir();
/// Path of a file under shared_dir(); a test failure (not a skip) when the
/// file is missing. Call it only after SALOAM_REQUIRE_SHARED_DATA().
std::filesystem::path shared_file(const std::string& relative);

/// What a test that needs shared data does, from check_shared_data().
enum class SharedDataAction { kRun, kSkip, kFail };
struct SharedDataCheck {
  SharedDataAction action = SharedDataAction::kRun;
  std::string reason;  ///< why the test skips or fails; empty for kRun
};
/// kRun when shared_dir() is a folder. When it is not: kFail if the data are
/// required (SALOAM_REQUIRE_SHARED_DATA=1, or CI=true with that variable
/// unset), else kSkip. Also kFail when CTest did not label the calling test
/// `shared-data` (see SALOAM_REQUIRE_SHARED_DATA).
SharedDataCheck check_shared_data();

}  // namespace saloam::testing

/// Declares that a test needs the development data (shared_dir()): without
/// it the test is skipped with the reason, or fails when the data are
/// required (CI). Write it as the first statement of the TEST/TEST_F/TEST_P
/// body: saloam_test() (cmake/SaloamModule.cmake) finds it there to give the
/// test the CTest label `shared-data`.
#define SALOAM_REQUIRE_SHARED_DATA()                                                          \
  do {                                                                                        \
    const auto saloam_shared_data_ = ::saloam::testing::check_shared_data();                  \
    if (saloam_shared_data_.action == ::saloam::testing::SharedDataAction::kFail)             \
      FAIL() << saloam_shared_data_.reason;                                                   \
    if (saloam_shared_data_.action == ::saloam::testing::SharedDataAction::kSkip)             \
      GTEST_SKIP() << saloam_shared_data_.reason;                                             \
  } while (false)

namespace saloam::testing {

/// A fresh temporary folder, removed with the object.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "saloam_test");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// The repository root.
std::filesystem::path source_dir();

/// Path of the built `saloam` program (for end-to-end tests).
std::filesystem::path cli_path();

/// `p` single-quoted for the shell.
std::string quoted(const std::filesystem::path& p);

/// The message of the InputError that `f` throws, or "no error".
template <class F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

/// Runs a shell command, returns its exit status; stdout+stderr go to `output`.
int run_command(const std::string& command, std::string* output = nullptr);

}  // namespace saloam::testing
