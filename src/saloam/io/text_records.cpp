#include "saloam/io/text_records.hpp"

#include <charconv>

#include <fmt/format.h>

#include "saloam/io/point_fields.hpp"

namespace saloam {

std::vector<std::string> split_words(std::string_view line) {
  std::vector<std::string> words;
  std::size_t i = 0;
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; };
  while (i < line.size()) {
    while (i < line.size() && blank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !blank(line[i])) ++i;
    if (i > start) words.emplace_back(line.substr(start, i - start));
  }
  return words;
}

TextRecords::TextRecords(std::span<const std::byte> bytes, std::filesystem::path file, std::string what,
                         std::size_t first_line)
    : bytes_(bytes), file_(std::move(file)), what_(std::move(what)), line_(first_line) {}

bool TextRecords::next_line(std::string_view& line) {
  if (offset_ >= bytes_.size()) return false;
  const std::string_view rest(reinterpret_cast<const char*>(bytes_.data()) + offset_, bytes_.size() - offset_);
  const std::size_t end = rest.find('\n');
  line = rest.substr(0, end);
  offset_ += end == std::string_view::npos ? rest.size() : end + 1;
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  ++line_;
  return true;
}

InputError TextRecords::error(const std::string& problem) const {
  return InputError(file_, fmt::format("{} {}: {}", what_, line_number(), problem));
}

double TextRecords::number(std::string_view word) const {
  const auto value = parse_number(word);
  if (!value) throw error(fmt::format("'{}' is not a number", word.substr(0, 40)));
  return *value;
}

std::size_t TextRecords::unsigned_value(const std::vector<std::string>& values, std::string_view key) const {
  if (values.size() != 1) throw error(fmt::format("{} needs one number", key));
  return unsigned_at(values[0], file_, line_number(), key);
}

std::size_t TextRecords::unsigned_at(std::string_view word, const std::filesystem::path& file, std::size_t line_no,
                                     std::string_view key) {
  std::size_t value = 0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (ec != std::errc() || end != word.data() + word.size() || value > (std::size_t{1} << 40)) {
    throw InputError(file, fmt::format("line {}: {} '{}' is not a count (0 .. 2^40)", line_no, key, word.substr(0, 40)));
  }
  return value;
}

}  // namespace saloam
