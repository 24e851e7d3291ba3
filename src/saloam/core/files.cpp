#include "saloam/core/files.hpp"

#include <cstdint>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace fs = std::filesystem;

namespace saloam {

void require_file(const fs::path& file, std::string_view what) {
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (status.type() == fs::file_type::regular) return;
  if (status.type() == fs::file_type::directory) throw InputError(file, fmt::format("is a directory, not a {}", what));
  if (status.type() == fs::file_type::not_found) throw InputError(file, fmt::format("{} not found", what));
  if (ec) throw InputError(file, fmt::format("cannot access {}: {}", what, ec.message()));
  throw InputError(file, fmt::format("is not a regular file (expected a {})", what));
}

namespace {

std::string size_text(std::uintmax_t bytes) {
  if (bytes < (1u << 20)) return fmt::format("{} bytes", bytes);
  return fmt::format("{:.1f} MiB", static_cast<double>(bytes) / static_cast<double>(1u << 20));
}

// An open descriptor of `file`, checked to be a regular file of at most `max_bytes`.
int open_regular(const fs::path& file, std::size_t max_bytes, std::string_view what) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) throw InputError(file, fmt::format("{} not found", what));
    throw InputError(file, fmt::format("cannot open {}: {}", what, std::strerror(errno)));
  }
  struct stat st {};
  std::string problem;
  if (::fstat(fd, &st) != 0) {
    problem = fmt::format("cannot read {}: {}", what, std::strerror(errno));
  } else if (S_ISDIR(st.st_mode)) {
    problem = fmt::format("is a directory, not a {}", what);
  } else if (!S_ISREG(st.st_mode)) {
    problem = fmt::format("is not a regular file (expected a {})", what);
  } else if (static_cast<std::uintmax_t>(st.st_size) > max_bytes) {
    problem = fmt::format("is {}, more than a {} may have ({})", size_text(static_cast<std::uintmax_t>(st.st_size)),
                          what, size_text(max_bytes));
  }
  if (problem.empty()) return fd;
  ::close(fd);
  throw InputError(file, problem);
}

}  // namespace

std::string read_file(const fs::path& file, std::size_t max_bytes, std::string_view what) {
  const int fd = open_regular(file, max_bytes, what);
  std::string bytes;
  char buffer[1 << 16];
  while (bytes.size() <= max_bytes) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      ::close(fd);
      throw InputError(file, fmt::format("cannot read {}: {}", what, std::strerror(error)));
    }
    if (n == 0) break;
    bytes.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  if (bytes.size() > max_bytes) {
    throw InputError(file, fmt::format("grew beyond {} while read (a {} may have no more)", size_text(max_bytes), what));
  }
  return bytes;
}

bool path_taken(const fs::path& path) {
  std::error_code ec;
  const auto type = fs::symlink_status(path, ec).type();
  return type != fs::file_type::not_found && type != fs::file_type::none;
}

void create_folder(const fs::path& folder) {
  if (folder.empty()) return;
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw InputError(folder, fmt::format("cannot create folder: {}", ec.message()));
  if (!fs::is_directory(folder, ec)) throw InputError(folder, "cannot create folder: a file of that name exists");
}

void create_parent_folder(const fs::path& file) {
  if (file.has_parent_path()) create_folder(file.parent_path());
}

std::string describe(const fs::filesystem_error& error) {
  const std::string reason = error.code().message();
  if (error.path1().empty()) return reason;
  if (error.path2().empty()) return fmt::format("{}: {}", error.path1().string(), reason);
  return fmt::format("{} -> {}: {}", error.path1().string(), error.path2().string(), reason);
}

bool is_valid_utf8(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto lead = static_cast<unsigned char>(text[i]);
    std::size_t length = 0;
    std::uint32_t code = 0;
    if (lead < 0x80) {
      ++i;
      continue;
    } else if ((lead & 0xe0) == 0xc0) {
      length = 2;
      code = lead & 0x1f;
    } else if ((lead & 0xf0) == 0xe0) {
      length = 3;
      code = lead & 0x0f;
    } else if ((lead & 0xf8) == 0xf0) {
      length = 4;
      code = lead & 0x07;
    } else {
      return false;
    }
    if (i + length > text.size()) return false;
    for (std::size_t k = 1; k < length; ++k) {
      const auto next = static_cast<unsigned char>(text[i + k]);
      if ((next & 0xc0) != 0x80) return false;
      code = (code << 6) | (next & 0x3f);
    }
    // Overlong forms, surrogates and code points beyond U+10FFFF are not UTF-8.
    const std::uint32_t smallest = length == 2 ? 0x80 : length == 3 ? 0x800 : 0x10000;
    if (code < smallest || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) return false;
    i += length;
  }
  return true;
}

std::string to_hex(std::string_view text) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * text.size());
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    hex += kDigits[byte >> 4];
    hex += kDigits[byte & 0x0f];
  }
  return hex;
}

std::optional<std::string> from_hex(std::string_view hex) {
  if (hex.size() % 2 != 0) return std::nullopt;
  const auto digit = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
  };
  std::string text;
  text.reserve(hex.size() / 2);
  for (std::size_t i = 0; i < hex.size(); i += 2) {
    const int high = digit(hex[i]), low = digit(hex[i + 1]);
    if (high < 0 || low < 0) return std::nullopt;
    text += static_cast<char>(high * 16 + low);
  }
  return text;
}

}  // namespace saloam
