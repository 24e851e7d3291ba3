#include "saloam/io/binary_file.hpp"

#include <fstream>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"

namespace saloam {

std::vector<std::byte> read_file_bytes(const std::filesystem::path& file, std::string_view what,
                                       std::size_t max_bytes) {
  require_file(file, what);
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  if (ec) throw InputError(file, fmt::format("cannot read size: {}", ec.message()));
  if (size > max_bytes) throw InputError(file, fmt::format("{} bytes: larger than {} bytes, not a {}", size, max_bytes, what));
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "cannot open for reading");
  std::vector<std::byte> bytes(size);
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size))) {
    throw InputError(file, "read failed");
  }
  return bytes;
}

void write_file_bytes(const std::filesystem::path& file, std::span<const std::byte> bytes) {
  write_file_atomically(file, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

}  // namespace saloam
