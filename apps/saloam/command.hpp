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

/// --no-calib of the runs (odom, slam): without it a missing calib.txt is an
/// error; with it poses.txt holds LiDAR-frame poses.
void add_no_calib_flag(CLI::App& app, bool& no_calib);

/// Checks for numeric options whose messages name the value: CLI11's
/// PositiveNumber prints its range as 300-digit numbers, and an unsigned
/// option silently wraps -1 to 18446744073709551615.
CLI::Validator positive_number();
CLI::Validator non_negative_integer();

/// The development data folder (../shared beside the repository), overridable
/// with the SALOAM_SHARED_DIR environment variable.
std::filesystem::path shared_dir();

}  // namespace saloam::cli
