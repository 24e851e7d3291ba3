#pragma once
// Helpers for the test suites.

#include <filesystem>
#include <string>

#include "saloam/core/error.hpp"

namespace saloam::testing {

/// ../shared (development data). Tests that need it call require_shared_data().
std::filesystem::path shared_dir();
/// Path of a file under shared/; fails the test (not skips) when missing,
/// since CI always has shared/.
std::filesystem::path shared_file(const std::string& relative);

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
