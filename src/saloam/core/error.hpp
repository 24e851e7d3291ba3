#pragma once
// Error types. Every error about bad input names the file (or option) and
// what is wrong with it, so the CLI can print it as is.

#include <filesystem>
#include <stdexcept>
#include <string>

namespace saloam {

/// Bad input data: a file that is missing, truncated or malformed.
class InputError : public std::runtime_error {
 public:
  InputError(const std::filesystem::path& file, const std::string& problem)
      : std::runtime_error(file.string() + ": " + problem), file_(file) {}
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
};

/// A configuration key or value that cannot be used.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace saloam
