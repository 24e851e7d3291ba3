#include "saloam/core/frame_range.hpp"

#include <algorithm>
#include <charconv>

#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace saloam {

FrameRange FrameRange::parse(const std::string& text, const std::string& option) {
  FrameRange range;
  if (text.empty()) return range;
  auto number = [&](const std::string& s) {
    std::size_t value = 0;
    const char* end = s.data() + s.size();
    const auto [ptr, ec] = std::from_chars(s.data(), end, value);
    if (s.empty() || ec != std::errc() || ptr != end) {
      throw ConfigError(fmt::format("{} '{}': expected A:B, A:, :B or A with frame numbers", option, text));
    }
    return value;
  };
  const auto colon = text.find(':');
  if (colon == std::string::npos) {
    range.first = number(text);
    range.end = range.first + 1;
    return range;
  }
  const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
  if (!a.empty()) range.first = number(a);
  if (!b.empty()) range.end = number(b);
  if (range.end <= range.first) throw ConfigError(fmt::format("{} '{}': B must be greater than A", option, text));
  return range;
}

std::pair<std::size_t, std::size_t> FrameRange::clip(std::size_t n, const std::string& option) const {
  const std::size_t e = std::min(end, n);
  if (first >= e) {
    throw ConfigError(fmt::format("{}: frames {}..{} are outside the sequence of {} frames", option, first,
                                  end == std::numeric_limits<std::size_t>::max() ? std::string("end")
                                                                                 : std::to_string(end),
                                  n));
  }
  return {first, e};
}

}  // namespace saloam
