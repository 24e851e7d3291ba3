#pragma once
// What every saloam program does around its command: logging, -v / -q,
// Ctrl-C, and one clear message and exit code for every error.

#include <exception>
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace saloam::cli {

/// Logs to stderr as "[level] message"; SPDLOG_LEVEL in the environment sets levels.
void setup_logging();

/// The -v / --verbose and -q / --quiet flags.
struct Verbosity {
  bool verbose = false;
  bool quiet = false;
  void add_to(CLI::App& app);
  /// Sets the log level; call after parsing.
  void apply() const;
};

/// Runs `command` and returns its exit code: Ctrl-C (or TERM) asks it to stop
/// and keep what it has (130; a second Ctrl-C leaves at once); an error is
/// logged as one message naming what failed (2).
int run_guarded(const std::function<int()>& command);

/// The whole main() of a program with one command (the trainers): logging,
/// the app with -v / -q, `add_options` (which adds the command's options and
/// returns what runs it), parsing, then run_guarded.
int run_program(int argc, char** argv, const std::string& description, const std::string& name,
                const std::function<std::function<int()>(CLI::App&)>& add_options);

/// An exception's text as an error message: plain and short
/// (plain_error_text), without a library's tags ("[json.exception...]") or
/// bare function names ("stoul").
std::string describe_exception(const std::exception& e);

/// Prints a command-line error (escaped, cut when long: an argument can hold
/// anything) and returns CLI11's exit code for it.
int print_parse_error(const CLI::ParseError& e);

}  // namespace saloam::cli
