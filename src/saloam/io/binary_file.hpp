#pragma once
// Whole binary files in and out, with errors naming the file (InputError).

#include <cstddef>
#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

namespace saloam {

/// The file's bytes. InputError when it is missing, a folder, unreadable, or
/// larger than `max_bytes` (so that a mistaken path cannot exhaust memory).
std::vector<std::byte> read_file_bytes(const std::filesystem::path& file, std::string_view what = "file",
                                       std::size_t max_bytes = std::size_t{4} << 30);
/// Writes `bytes` to `file` through an AtomicFile (core/output_file.hpp:
/// parent folders created, the file appears whole or not at all).
void write_file_bytes(const std::filesystem::path& file, std::span<const std::byte> bytes);

}  // namespace saloam
