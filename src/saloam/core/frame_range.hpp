#pragma once
// Frame ranges as given on the command line: "A:B" (B exclusive), "A:" (to
// the end), ":B" (from the start) or "A" (the single frame A).

#include <cstddef>
#include <limits>
#include <string>
#include <utility>

namespace saloam {

struct FrameRange {
  std::size_t first = 0;
  std::size_t end = std::numeric_limits<std::size_t>::max();  ///< exclusive; max = to the end

  /// Parses `text` (empty = everything). Throws ConfigError naming `option`.
  static FrameRange parse(const std::string& text, const std::string& option = "--frames");
  /// [first, end) clipped to a sequence of n frames; throws ConfigError when empty.
  [[nodiscard]] std::pair<std::size_t, std::size_t> clip(std::size_t n, const std::string& option = "--frames") const;
};

}  // namespace saloam
