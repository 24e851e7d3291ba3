#include "saloam/core/files.hpp"

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
