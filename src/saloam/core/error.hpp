#pragma once
// Error types. Every error about bad input names the file (or option) and
// what is wrong with it, so the CLI can print it as is: the text is plain
// (control bytes such as NUL escaped) and short (a problem quoting a 10 MB
// line is cut), whatever the input held.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace saloam {

/// A problem's text as an error prints it: bytes below 0x20 (but tab) and
/// 0x7f written as \xNN, and cut after `max_bytes` with a note of how much
/// was left out.
std::string plain_error_text(std::string_view text, std::size_t max_bytes = 600);

/// Bad input data: a file that is missing, truncated or malformed.
class InputError : public std::runtime_error {
 public:
  InputError(const std::filesystem::path& file, const std::string& problem)
      : std::runtime_error(plain_error_text(file.string(), 4096) + ": " + plain_error_text(problem)), file_(file) {}
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
};

/// A configuration key or value that cannot be used.
class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(const std::string& problem) : std::runtime_error(plain_error_text(problem)) {}
};

}  // namespace saloam
