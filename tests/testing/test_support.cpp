#include "testing/test_support.hpp"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <random>

#include <gtest/gtest.h>

namespace saloam::testing {

std::filesystem::path shared_dir() {
  if (const char* env = std::getenv("SALOAM_SHARED_DIR")) return env;
  return SALOAM_TEST_SHARED_DIR;
}

std::filesystem::path shared_file(const std::string& relative) {
  const auto path = shared_dir() / relative;
  EXPECT_TRUE(std::filesystem::exists(path)) << "missing shared test data: " << path;
  return path;
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
