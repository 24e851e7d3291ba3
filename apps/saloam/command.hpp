#pragma once
// Subcommand registry of the `saloam` program. Each cmd_*.cpp registers one
// subcommand with a static `CommandRegistration`; main() builds the CLI from
// the registry. Commands only parse options, call the library and print.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "saloam/core/config.hpp"

namespace saloam::cli {

/// Adds options to `app` and returns the function that runs the command
/// (called after parsing; returns the exit code).
using CommandSetup = std::function<std::function<int()>(CLI::App& app)>;

struct Command {
  std::string name;
  std::string description;
  int order;  ///< position in --help
  CommandSetup setup;
};

std::vector<Command>& command_registry();

struct CommandRegistration {
  explicit CommandRegistration(Command command) { command_registry().push_back(std::move(command)); }
};

/// --config FILE and --set key=value (repeatable), shared by every command
/// that runs the pipeline. Call `resolve()` after parsing.
struct ConfigOptions {
  std::string config_file;
  std::vector<std::string> overrides;
  void add_to(CLI::App& app);
  [[nodiscard]] SaloamConfig resolve() const;
};

/// The development data folder (../shared beside the repository), overridable
/// with the SALOAM_SHARED_DIR environment variable.
std::filesystem::path shared_dir();

}  // namespace saloam::cli
