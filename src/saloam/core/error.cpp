#include "saloam/core/error.hpp"

#include <fmt/format.h>

namespace saloam {

std::string plain_error_text(std::string_view text, std::size_t max_bytes) {
  std::string out;
  out.reserve(std::min(text.size(), max_bytes) + 16);
  std::size_t used = 0;
  for (; used < text.size() && out.size() < max_bytes; ++used) {
    const auto byte = static_cast<unsigned char>(text[used]);
    if ((byte < 0x20 && byte != '\t') || byte == 0x7f) {
      out += fmt::format("\\x{:02x}", byte);
    } else {
      out += static_cast<char>(byte);
    }
  }
  if (used < text.size()) out += fmt::format("... ({} more bytes)", text.size() - used);
  return out;
}

}  // namespace saloam
