#include "saloam/core/files.hpp"

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

}  // namespace saloam
