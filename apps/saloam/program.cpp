#include "program.hpp"

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include <iostream>

#include <nlohmann/json.hpp>
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
    int code = command();
    // What went to standard output must have arrived (`saloam eval ... > /dev/full`).
    errno = 0;
    std::cout.flush();
    if (std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout.good()) {
      spdlog::error("standard output: cannot write ({})", std::strerror(errno != 0 ? errno : EIO));
      if (code == 0) code = 2;
    }
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
    spdlog::error("{}", describe_exception(e));
  }
  return 2;
}

int run_program(int argc, char** argv, const std::string& description, const std::string& name,
                const std::function<std::function<int()>(CLI::App&)>& add_options) {
  setup_logging();
  CLI::App app{description, name};
  Verbosity verbosity;
  verbosity.add_to(app);
  const auto run = add_options(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  verbosity.apply();
  return run_guarded(run);
}

std::string describe_exception(const std::exception& e) {
  std::string_view text = e.what();
  if (dynamic_cast<const nlohmann::json::exception*>(&e)) {
    // "[json.exception.type_error.316] invalid UTF-8 byte ...": the library's tag is no news to a user.
    if (const auto end = text.find("] "); text.starts_with("[json.exception.") && end != std::string_view::npos) {
      text.remove_prefix(end + 2);
    }
    return "JSON: " + plain_error_text(text);
  }
  // std::stoi and its siblings throw with their own name as the whole text.
  if (dynamic_cast<const std::invalid_argument*>(&e) || dynamic_cast<const std::out_of_range*>(&e)) {
    if (text.starts_with("sto")) return "a number that is not one or is out of range (" + plain_error_text(text) + ")";
  }
  if (dynamic_cast<const std::bad_alloc*>(&e)) return "out of memory";
  return plain_error_text(text);
}

int print_parse_error(const CLI::ParseError& e) {
  std::cerr << plain_error_text(e.what()) << "\nRun with --help for more information.\n";
  return e.get_exit_code();
}

}  // namespace saloam::cli
