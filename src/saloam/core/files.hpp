#pragma once
// Checks and folder creation at the file-system boundary, so that what the
// user sees is "PATH: problem" (InputError), never a raw
// std::filesystem::filesystem_error text.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace saloam {

/// InputError unless `file` is a readable regular file (symlinks followed):
/// "<what> not found", "is a directory, not a <what>", or "is not a regular file".
void require_file(const std::filesystem::path& file, std::string_view what = "file");

/// The bytes of `file`, which must be a regular file (links followed) of at
/// most `max_bytes`. It is opened without blocking and checked before it is
/// read: a folder, a FIFO or a device (a link to /dev/zero) in its place is
/// refused with an InputError naming it, never waited on or read without end.
std::string read_file(const std::filesystem::path& file, std::size_t max_bytes, std::string_view what = "file");

/// Whether something (a file, folder, link, even a dangling one) exists at `path`.
bool path_taken(const std::filesystem::path& path);

/// Creates `folder` and its parents; InputError naming the folder and the
/// system's reason (e.g. a file of that name exists, permission denied).
void create_folder(const std::filesystem::path& folder);
/// create_folder() of the parent of `file`, when it has one.
void create_parent_folder(const std::filesystem::path& file);

/// Whether `text` is valid UTF-8 (JSON strings must be; a path need not be).
bool is_valid_utf8(std::string_view text);
/// The bytes of `text` as lower-case hexadecimal, two digits a byte.
std::string to_hex(std::string_view text);
/// The bytes to_hex() wrote; nullopt when `hex` is not such a text.
std::optional<std::string> from_hex(std::string_view hex);

/// "PATH: reason" for a filesystem_error (path1 when set, else the message).
std::string describe(const std::filesystem::filesystem_error& error);

}  // namespace saloam
