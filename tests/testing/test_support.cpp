#include "testing/test_support.hpp"

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <random>

#include <gtest/gtest.h>

namespace saloam::testing {

namespace {

/// Whether the environment variable `name` holds a true value (1, true, yes,
/// on; any case); `fallback` when it is unset or empty.
bool env_flag(const char* name, bool fallback) {
  const char* value = std::getenv(name);
  if (!value || !*value) return fallback;
  std::string v(value);
  std::transform(v.begin(), v.end(), v.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return v == "1" || v == "true" || v == "yes" || v == "on";
}

}  // namespace

std::filesystem::path shared_dir() {
  if (const char* env = std::getenv("SALOAM_SHARED_DIR")) return env;
  return SALOAM_TEST_SHARED_DIR;
}

std::filesystem::path shared_file(const std::string& relative) {
  const auto path = shared_dir() / relative;
  EXPECT_TRUE(std::filesystem::exists(path))
      << "missing shared test data: " << path
      << " (a test that reads shared data starts with SALOAM_REQUIRE_SHARED_DATA())";
  return path;
}

SharedDataCheck check_shared_data() {
  // saloam_test() runs every CTest test with SALOAM_TEST_SHARED_DATA_LABEL set
  // to 1 for those it labelled shared-data and 0 for the rest; 0 here means
  // its source scan missed this test's SALOAM_REQUIRE_SHARED_DATA().
  if (const char* label = std::getenv("SALOAM_TEST_SHARED_DATA_LABEL"); label && std::string(label) == "0") {
    return {SharedDataAction::kFail,
            "SALOAM_REQUIRE_SHARED_DATA() is not the first statement of this test's body, so CTest did not "
            "label the test shared-data (see saloam_test in cmake/SaloamModule.cmake)"};
  }
  const auto dir = shared_dir();
  if (std::filesystem::is_directory(dir)) return {};
  // An explicit SALOAM_REQUIRE_SHARED_DATA wins; otherwise CI (CI=true, as
  // .ci/run and most CI services set) requires the data.
  if (env_flag("SALOAM_REQUIRE_SHARED_DATA", env_flag("CI", false))) {
    return {SharedDataAction::kFail, "shared development data required (CI=true or SALOAM_REQUIRE_SHARED_DATA=1) but " +
                                         dir.string() + " is not a folder"};
  }
  return {SharedDataAction::kSkip,
          "needs the shared development data, not found at " + dir.string() +
              " (../shared beside the repository, or $SALOAM_SHARED_DIR); with CI=true or "
              "SALOAM_REQUIRE_SHARED_DATA=1 this is a failure"};
}

TempDir::TempDir(const std::string& prefix) {
  std::random_device rd;
  const auto base = std::filesystem::temp_directory_path();
  do {
    path_ = base / (prefix + "_" + std::to_string(rd()));
  } while (std::filesystem::exists(path_));
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::filesystem::path source_dir() { return SALOAM_TEST_SOURCE_DIR; }

std::string quoted(const std::filesystem::path& p) {
  std::string q(1, '\'');  // built with append: GCC 12 warns falsely on "'" + s
  q.append(p.string());
  q.push_back('\'');
  return q;
}

std::filesystem::path cli_path() { return SALOAM_CLI_PATH; }

int run_command(const std::string& command, std::string* output) {
  const std::string full = command + " 2>&1";
  FILE* pipe = popen(full.c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buffer{};
  std::string text;
  while (fgets(buffer.data(), static_cast<int>(buffer.size()), pipe)) text += buffer.data();
  const int status = pclose(pipe);
  if (output) *output = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace saloam::testing
