#pragma once
// Line-by-line reading of the text parts of binary files (PCD and PLY
// headers, ASCII point data) straight from their bytes, with errors that
// name the file and the line. Lines end at '\n'; a '\r' before it is dropped.

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/error.hpp"

namespace saloam {

/// The whitespace-separated words of `line`.
std::vector<std::string> split_words(std::string_view line);

class TextRecords {
 public:
  /// `what` names a line in errors ("header line", "line"); lines are
  /// numbered from `first_line`.
  TextRecords(std::span<const std::byte> bytes, std::filesystem::path file, std::string what,
              std::size_t first_line = 1);

  /// The next line (without its end), false at the end of the bytes.
  bool next_line(std::string_view& line);
  /// The number of the line next_line() returned last.
  [[nodiscard]] std::size_t line_number() const { return line_ - 1; }
  /// Bytes consumed so far (the start of the next line).
  [[nodiscard]] std::size_t offset() const { return offset_; }

  /// InputError "FILE: <what> N: problem" for the current line.
  [[nodiscard]] InputError error(const std::string& problem) const;
  /// A number (nan and inf accepted); error() when the word is not one.
  [[nodiscard]] double number(std::string_view word) const;
  /// The single unsigned integer of `values` (a header entry named `key`).
  [[nodiscard]] std::size_t unsigned_value(const std::vector<std::string>& values, std::string_view key) const;
  /// An unsigned integer up to 2^40 (counts and sizes); InputError naming
  /// the line and the key otherwise.
  static std::size_t unsigned_at(std::string_view word, const std::filesystem::path& file, std::size_t line_no,
                                 std::string_view key);

 private:
  std::span<const std::byte> bytes_;
  std::filesystem::path file_;
  std::string what_;
  std::size_t offset_ = 0;
  std::size_t line_;
};

}  // namespace saloam
