#pragma once
// MD5 (RFC 1321), for comparing decoded fields with the digests Ouster's SDK
// writes (hashlib.md5 of numpy arrays' bytes). Tests only: not for security.

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

namespace saloam::testing {

class Md5 {
 public:
  void update(std::span<const std::uint8_t> data) {
    for (std::uint8_t byte : data) {
      buffer_[fill_++] = byte;
      if (fill_ == 64) {
        block();
        fill_ = 0;
      }
    }
    length_ += data.size();
  }
  template <class T>
  void update_values(std::span<const T> values) {
    update({reinterpret_cast<const std::uint8_t*>(values.data()), values.size_bytes()});  // little-endian host
  }
  /// The digest as 32 lowercase hex digits; the object is spent afterwards.
  std::string hex() {
    const std::uint64_t bits = length_ * 8;
    const std::uint8_t pad = 0x80;
    update({&pad, 1});
    const std::uint8_t zero = 0;
    while (fill_ != 56) update({&zero, 1});
    std::array<std::uint8_t, 8> len{};
    for (int i = 0; i < 8; ++i) len[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(bits >> (8 * i));
    update(len);
    std::string out;
    static constexpr char kHex[] = "0123456789abcdef";
    for (std::uint32_t word : state_) {
      for (int i = 0; i < 4; ++i) {
        const auto b = static_cast<std::uint8_t>(word >> (8 * i));
        out += kHex[b >> 4];
        out += kHex[b & 15];
      }
    }
    return out;
  }

 private:
  static std::uint32_t rotl(std::uint32_t x, int c) { return (x << c) | (x >> (32 - c)); }
  void block() {
    static constexpr std::array<int, 64> kShift{7, 12, 17, 22, 7, 12, 17, 22, 7, 12, 17, 22, 7, 12, 17, 22,
                                                5, 9,  14, 20, 5, 9,  14, 20, 5, 9,  14, 20, 5, 9,  14, 20,
                                                4, 11, 16, 23, 4, 11, 16, 23, 4, 11, 16, 23, 4, 11, 16, 23,
                                                6, 10, 15, 21, 6, 10, 15, 21, 6, 10, 15, 21, 6, 10, 15, 21};
    static const std::array<std::uint32_t, 64> kK = [] {
      std::array<std::uint32_t, 64> k{};
      for (int i = 0; i < 64; ++i) {
        k[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(std::fabs(std::sin(i + 1.0)) * 4294967296.0);
      }
      return k;
    }();
    std::array<std::uint32_t, 16> m{};
    for (int i = 0; i < 16; ++i) {
      std::memcpy(&m[static_cast<std::size_t>(i)], &buffer_[static_cast<std::size_t>(4 * i)], 4);
    }
    std::uint32_t a = state_[0], b = state_[1], c = state_[2], d = state_[3];
    for (int i = 0; i < 64; ++i) {
      std::uint32_t f = 0;
      int g = 0;
      if (i < 16) {
        f = (b & c) | (~b & d);
        g = i;
      } else if (i < 32) {
        f = (d & b) | (~d & c);
        g = (5 * i + 1) % 16;
      } else if (i < 48) {
        f = b ^ c ^ d;
        g = (3 * i + 5) % 16;
      } else {
        f = c ^ (b | ~d);
        g = (7 * i) % 16;
      }
      const std::uint32_t next = d;
      d = c;
      c = b;
      b = b + rotl(a + f + kK[static_cast<std::size_t>(i)] + m[static_cast<std::size_t>(g)], kShift[static_cast<std::size_t>(i)]);
      a = next;
    }
    state_[0] += a;
    state_[1] += b;
    state_[2] += c;
    state_[3] += d;
  }

  std::array<std::uint32_t, 4> state_{0x67452301U, 0xefcdab89U, 0x98badcfeU, 0x10325476U};
  std::array<std::uint8_t, 64> buffer_{};
  std::size_t fill_ = 0;
  std::uint64_t length_ = 0;
};

}  // namespace saloam::testing
