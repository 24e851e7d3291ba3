#pragma once
// A scratch file for harnesses whose reader takes only files (SQLite, the
// MCAP reader's seeks): one per process, removed when it ends.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <system_error>

#include <fmt/format.h>

namespace saloam::fuzz {

class ScratchFile {
 public:
  explicit ScratchFile(std::string_view extension)
      : path_(std::filesystem::temp_directory_path() / fmt::format("saloam_fuzz_{}{}", ::getpid(), extension)) {}
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  ~ScratchFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  /// The file, holding `size` bytes of `data` (and nothing else).
  const std::filesystem::path& holding(const std::uint8_t* data, std::size_t size) const {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    return path_;
  }

 private:
  std::filesystem::path path_;
};

}  // namespace saloam::fuzz
