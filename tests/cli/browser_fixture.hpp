#pragma once
// What the browser tests share: headless Chromium on a page or a URL, and a
// `saloam` child process that serves pages (--serve) until it is sent Ctrl-C.

#include <fcntl.h>
#include <spawn.h>
#include <sys/types.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "testing/test_support.hpp"
#include "viewer/viewer_fixture.hpp"

extern char** environ;

namespace saloam::testing {

/// Headless Chromium, or a skip (a failure with CI=true) when it is not installed.
#define SALOAM_REQUIRE_CHROMIUM()                                                                     \
  do {                                                                                                \
    if (::saloam::testing::run_command("command -v chromium") != 0) {                                 \
      const char* ci = std::getenv("CI");                                                             \
      if (ci && std::string(ci) == "true") FAIL() << "chromium is not installed (CI=true)";           \
      GTEST_SKIP() << "chromium is not installed (Debian package chromium; scripts/install_deps.sh)"; \
    }                                                                                                 \
  } while (false)

/// Headless Chromium with `args` (e.g. --dump-dom) on `url`; its output.
inline std::string chromium_url(const TempDir& tmp, const std::string& args, const std::string& url) {
  std::string output;
  const std::string command = fmt::format(
      "timeout 120 chromium --headless=new --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader "
      "--disable-dev-shm-usage --user-data-dir={} --enable-logging=stderr --v=0 {} {}",
      quoted(tmp / "chromium_profile"), args, quoted(std::filesystem::path(url)));
  run_command(command, &output);
  return output;
}

/// The same on a page on disk.
inline std::string chromium(const TempDir& tmp, const std::string& args, const std::filesystem::path& page) {
  return chromium_url(tmp, args, "file://" + std::filesystem::absolute(page).string());
}

/// `saloam ARGS...` as a child process, its output into `log`; -1 when it cannot start.
inline pid_t spawn_saloam(const std::vector<std::string>& args, const std::filesystem::path& log) {
  std::vector<std::string> argv_text{cli_path().string()};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = -1;
  if (posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

/// The port of the first http://127.0.0.1:PORT/ that `log` names, waiting up
/// to `seconds` for it; nullopt when none appears.
inline std::optional<int> served_port(const std::filesystem::path& log, double seconds = 15) {
  const std::string prefix = "http://127.0.0.1:";
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (true) {
    const std::string text = read_text(log);
    const std::size_t at = text.find(prefix);
    if (at != std::string::npos) {
      const std::size_t digits = at + prefix.size();
      const std::size_t end = text.find_first_not_of("0123456789", digits);
      if (end != std::string::npos && end > digits && text[end] == '/') return std::stoi(text.substr(digits, end - digits));
    }
    if (std::chrono::steady_clock::now() > until) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

}  // namespace saloam::testing
