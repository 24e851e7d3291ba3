#pragma once
// The scan files of a folder, in order, and what their names say.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

namespace saloam {

struct ScanFiles {
  std::vector<std::filesystem::path> files;
  /// Each file's timestamp [s] when every name is one: a stem with a decimal
  /// point ("1317384512.123456", seconds) or of 16 to 19 digits (nanoseconds,
  /// as ROS 2 tools name them).
  std::optional<std::vector<double>> stamps;
};

/// The regular files of `folder` ending in `extension` (".pcd"), ordered:
/// by number when every stem is a frame number (up to 10 digits, as KITTI raw names them; then they
/// must follow each other without a gap, or every later scan would be paired
/// with the wrong time and pose), by time when every stem is a timestamp,
/// else by name. InputError naming the folder when it cannot be listed or
/// holds no such file, or naming the missing frame.
ScanFiles list_scan_files(const std::filesystem::path& folder, std::string_view extension);

/// Whether `folder` holds at least one regular file ending in `extension`.
bool has_files_with_extension(const std::filesystem::path& folder, std::string_view extension);

}  // namespace saloam
