#pragma once
// Shared by the libFuzzer harnesses (docs/reliability.md). A harness feeds
// one reader the fuzzer's bytes and checks the reader's contract: it returns
// a value that satisfies its documented invariants, or throws one of the
// project's documented error types naming the input. Anything else (another
// exception type, a crash, a sanitizer report, a broken invariant) aborts,
// which libFuzzer and the replay test both report as a failure.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"

namespace saloam::fuzz {

inline std::span<const std::byte> as_bytes(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const std::byte*>(data), size};
}

inline std::string as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

[[noreturn]] inline void violated(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: reader contract violated: %s\n", file, line, condition);
  std::abort();
}

/// Readers warn about dropped points and the like; a fuzzer runs millions of
/// inputs, so logging is switched off once.
inline void quiet_logs() {
  static const bool done = [] {
    spdlog::set_level(spdlog::level::off);
    return true;
  }();
  (void)done;
}

/// An InputError must name the input it was given and say what is wrong.
inline void check_names_input(const InputError& error, const std::filesystem::path& input);

}  // namespace saloam::fuzz

#define SALOAM_FUZZ_CHECK(condition) \
  ((condition) ? static_cast<void>(0) : ::saloam::fuzz::violated(#condition, __FILE__, __LINE__))

inline void saloam::fuzz::check_names_input(const InputError& error, const std::filesystem::path& input) {
  const std::string_view what = error.what();
  const std::string prefix = input.string() + ": ";
  SALOAM_FUZZ_CHECK(error.file() == input);
  SALOAM_FUZZ_CHECK(what.starts_with(prefix));
  SALOAM_FUZZ_CHECK(what.size() > prefix.size());
}
