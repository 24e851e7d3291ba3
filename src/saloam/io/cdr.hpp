#pragma once
// OMG CDR (XCDR1, "plain CDR"), the serialisation ROS 2 messages are stored
// in (rosbag2 .db3 and .mcap files with serialization_format / message
// encoding "cdr"):
//   4-byte encapsulation header: 0x00 0x00 big-endian, 0x00 0x01
//   little-endian (then 2 option bytes, ignored);
//   every primitive aligned to its own size, counted from the byte after
//   that header; strings: uint32 length including the terminating NUL, the
//   characters, NUL; sequences: uint32 element count, the elements; bool 1 byte.
// CdrReader checks every read against the bytes left (InputError naming
// the file, prefixed by a context such as "topic /points, message 3");
// CdrWriter writes what CdrReader reads, in either byte order.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/error.hpp"

namespace saloam {

class CdrReader {
 public:
  /// Reads the encapsulation header of `bytes` (InputError when it is cut
  /// off or is not plain CDR of either byte order).
  CdrReader(std::span<const std::byte> bytes, const std::filesystem::path& file, std::string_view context);

  [[nodiscard]] InputError error(const std::string& problem) const;
  [[nodiscard]] bool big_endian() const { return big_endian_; }
  /// `n` bytes as they are (no alignment).
  std::span<const std::byte> take(std::size_t n, std::string_view what);
  std::uint8_t u8(std::string_view what);
  std::uint32_t u32(std::string_view what);
  std::int32_t i32(std::string_view what) { return static_cast<std::int32_t>(u32(what)); }
  /// A string of at most `max_length` characters (NUL excluded).
  std::string string(std::string_view what, std::size_t max_length);
  [[nodiscard]] std::size_t left() const { return bytes_.size() - at_; }

 private:
  void align(std::size_t n, std::string_view what);

  std::span<const std::byte> bytes_;
  const std::filesystem::path& file_;
  std::string_view context_;
  std::size_t at_ = 4;  ///< alignment counts from here
  bool big_endian_ = false;
};

class CdrWriter {
 public:
  explicit CdrWriter(bool big_endian = false);
  void u8(std::uint8_t v);
  void u32(std::uint32_t v);
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void string(std::string_view s);
  /// Raw bytes, no alignment (the content of a uint8 sequence).
  void bytes(std::span<const std::byte> b);
  /// Reserves `n` unaligned bytes and returns where they start.
  std::byte* extend(std::size_t n);
  [[nodiscard]] bool big_endian() const { return big_endian_; }
  [[nodiscard]] std::vector<std::byte> take() && { return std::move(out_); }

 private:
  void align(std::size_t n);
  std::vector<std::byte> out_;
  bool big_endian_;
};

}  // namespace saloam
