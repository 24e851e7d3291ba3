#pragma once
// Checks and folder creation at the file-system boundary, so that what the
// user sees is "PATH: problem" (InputError), never a raw
// std::filesystem::filesystem_error text.

#include <filesystem>
#include <string>
#include <string_view>

namespace saloam {

/// InputError unless `file` is a readable regular file (symlinks followed):
/// "<what> not found", "is a directory, not a <what>", or "is not a regular file".
void require_file(const std::filesystem::path& file, std::string_view what = "file");

/// Creates `folder` and its parents; InputError naming the folder and the
/// system's reason (e.g. a file of that name exists, permission denied).
void create_folder(const std::filesystem::path& folder);
/// create_folder() of the parent of `file`, when it has one.
void create_parent_folder(const std::filesystem::path& file);

/// "PATH: reason" for a filesystem_error (path1 when set, else the message).
std::string describe(const std::filesystem::filesystem_error& error);

}  // namespace saloam
