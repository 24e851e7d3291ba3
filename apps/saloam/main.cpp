// saloam: semantic-aided LiDAR SLAM with loop closure. Thin command-line
// front end: every subcommand lives in its own cmd_*.cpp.

#include <algorithm>
#include <csignal>
#include <cstdio>

#include <spdlog/cfg/env.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"

namespace {

extern "C" void on_signal(int) {
  if (saloam::stop_requested()) std::_Exit(130);  // second Ctrl-C: leave now
  saloam::request_stop();
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_default_logger(spdlog::stderr_color_mt("saloam"));
  spdlog::set_pattern("[%l] %v");
  spdlog::cfg::load_env_levels();

  CLI::App app{"saloam: semantic-aided LiDAR SLAM with loop closure (SA-LOAM)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "saloam 0.1.0");
  bool verbose = false, quiet = false;
  app.add_flag("-v,--verbose", verbose, "Debug logging");
  app.add_flag("-q,--quiet", quiet, "Warnings and errors only");

  auto& registry = saloam::cli::command_registry();
  std::stable_sort(registry.begin(), registry.end(), [](const auto& a, const auto& b) { return a.order < b.order; });
  std::function<int()> runner;
  for (auto& command : registry) {
    CLI::App* sub = app.add_subcommand(command.name, command.description);
    auto run = command.setup(*sub);
    sub->callback([run, &runner] { runner = run; });
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (verbose) spdlog::set_level(spdlog::level::debug);
  if (quiet) spdlog::set_level(spdlog::level::warn);

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    const int code = runner ? runner() : 1;
    if (saloam::stop_requested()) {
      spdlog::warn("interrupted: results written so far are kept");
      return 130;
    }
    return code;
  } catch (const saloam::InputError& e) {
    spdlog::error("{}", e.what());
  } catch (const saloam::ConfigError& e) {
    spdlog::error("configuration: {}", e.what());
  } catch (const std::filesystem::filesystem_error& e) {
    spdlog::error("{}", saloam::describe(e));  // "PATH: reason", not the library's raw text
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
  return 2;
}
