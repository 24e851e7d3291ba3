#include "saloam/io/cdr.hpp"

#include <bit>
#include <cstring>

#include <fmt/format.h>

namespace saloam {
namespace {

std::uint32_t byte_swapped(std::uint32_t v) {
  return ((v & 0xFFu) << 24) | ((v & 0xFF00u) << 8) | ((v >> 8) & 0xFF00u) | (v >> 24);
}

constexpr bool kHostLittle = std::endian::native == std::endian::little;

}  // namespace

CdrReader::CdrReader(std::span<const std::byte> bytes, const std::filesystem::path& file, std::string_view context)
    : bytes_(bytes), file_(file), context_(context) {
  if (bytes.size() < 4) throw error(fmt::format("{} bytes: no CDR encapsulation header", bytes.size()));
  const auto id = static_cast<unsigned>(bytes[1]) | static_cast<unsigned>(bytes[0]) << 8;
  if (id > 1) throw error(fmt::format("CDR representation 0x{:04x}: only plain CDR (0x0000, 0x0001) is read", id));
  big_endian_ = id == 0;
}

InputError CdrReader::error(const std::string& problem) const {
  return InputError(file_, fmt::format("{}: {}", context_, problem));
}

void CdrReader::align(std::size_t n, std::string_view what) {
  const std::size_t pad = (n - (at_ - 4) % n) % n;
  take(pad, what);
}

std::span<const std::byte> CdrReader::take(std::size_t n, std::string_view what) {
  if (n > bytes_.size() - at_) {
    throw error(fmt::format("cut off in {} ({} bytes needed at byte {}, {} left)", what, n, at_, bytes_.size() - at_));
  }
  const auto out = bytes_.subspan(at_, n);
  at_ += n;
  return out;
}

std::uint8_t CdrReader::u8(std::string_view what) { return static_cast<std::uint8_t>(take(1, what)[0]); }

std::uint32_t CdrReader::u32(std::string_view what) {
  align(4, what);
  std::uint32_t v;
  std::memcpy(&v, take(4, what).data(), 4);
  return big_endian_ == kHostLittle ? byte_swapped(v) : v;
}

std::string CdrReader::string(std::string_view what, std::size_t max_length) {
  const std::size_t n = u32(what);
  if (n == 0) return {};  // some writers leave out the NUL of an empty string
  if (n - 1 > max_length) throw error(fmt::format("{} of {} bytes: longer than {}", what, n - 1, max_length));
  const auto bytes = take(n, what);
  if (bytes[n - 1] != std::byte{0}) throw error(fmt::format("{} does not end with NUL", what));
  return {reinterpret_cast<const char*>(bytes.data()), n - 1};
}

CdrWriter::CdrWriter(bool big_endian) : out_{std::byte{0}, static_cast<std::byte>(big_endian ? 0 : 1), std::byte{0}, std::byte{0}}, big_endian_(big_endian) {}

void CdrWriter::align(std::size_t n) { out_.resize(out_.size() + (n - (out_.size() - 4) % n) % n, std::byte{0}); }

std::byte* CdrWriter::extend(std::size_t n) {
  out_.resize(out_.size() + n);
  return out_.data() + out_.size() - n;
}

void CdrWriter::u8(std::uint8_t v) { out_.push_back(static_cast<std::byte>(v)); }

void CdrWriter::u32(std::uint32_t v) {
  align(4);
  if (big_endian_ == kHostLittle) v = byte_swapped(v);
  std::memcpy(extend(4), &v, 4);
}

void CdrWriter::string(std::string_view s) {
  u32(static_cast<std::uint32_t>(s.size() + 1));
  std::memcpy(extend(s.size()), s.data(), s.size());
  out_.push_back(std::byte{0});
}

void CdrWriter::bytes(std::span<const std::byte> b) {
  if (!b.empty()) std::memcpy(extend(b.size()), b.data(), b.size());
}

}  // namespace saloam
