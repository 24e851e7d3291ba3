#include "program.hpp"

#include <csignal>
#include <cstdlib>
#include <filesystem>

#include <spdlog/cfg/env.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"

namespace saloam::cli {
namespace {

extern "C" void on_signal(int) {
  if (saloam::stop_requested()) std::_Exit(130);  // second Ctrl-C: leave now
  saloam::request_stop();
}

}  // namespace

void setup_logging() {
  spdlog::set_default_logger(spdlog::stderr_color_mt("saloam"));
  spdlog::set_pattern("[%l] %v");
  spdlog::cfg::load_env_levels();
}

void Verbosity::add_to(CLI::App& app) {
  app.add_flag("-v,--verbose", verbose, "Debug logging");
  app.add_flag("-q,--quiet", quiet, "Warnings and errors only");
}

void Verbosity::apply() const {
  if (verbose) spdlog::set_level(spdlog::level::debug);
  if (quiet) spdlog::set_level(spdlog::level::warn);
}

int run_guarded(const std::function<int()>& command) {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    const int code = command();
    if (stop_requested()) {
      spdlog::warn("interrupted: results written so far are kept");
      return 130;
    }
    return code;
  } catch (const InputError& e) {
    spdlog::error("{}", e.what());
  } catch (const ConfigError& e) {
    spdlog::error("configuration: {}", e.what());
  } catch (const std::filesystem::filesystem_error& e) {
    spdlog::error("{}", describe(e));  // "PATH: reason", not the library's raw text
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
  return 2;
}

}  // namespace saloam::cli
