#pragma once
// The real Ouster captures of ../shared/data/ouster_pcaps, which an older
// copy of the shared data may lack: after SALOAM_REQUIRE_SHARED_DATA() (which
// labels the test shared-data), SALOAM_REQUIRE_OUSTER_PCAPS() skips the test
// when that folder is missing, or fails it when the shared data are required
// (SALOAM_REQUIRE_SHARED_DATA=1, or CI=true with it unset), as the shared
// data's own check does.

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "testing/test_support.hpp"

namespace saloam::testing {

inline std::filesystem::path ouster_pcaps_dir() { return shared_dir() / "data" / "ouster_pcaps"; }

inline bool shared_data_required() {
  const auto flag = [](const char* name, bool fallback) {
    const char* value = std::getenv(name);
    if (!value || !*value) return fallback;
    std::string v(value);
    std::transform(v.begin(), v.end(), v.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return v == "1" || v == "true" || v == "yes" || v == "on";
  };
  return flag("SALOAM_REQUIRE_SHARED_DATA", flag("CI", false));
}

}  // namespace saloam::testing

#define SALOAM_REQUIRE_OUSTER_PCAPS()                                                               \
  do {                                                                                              \
    if (!std::filesystem::is_directory(::saloam::testing::ouster_pcaps_dir())) {                    \
      if (::saloam::testing::shared_data_required())                                                \
        FAIL() << "shared data required but " << ::saloam::testing::ouster_pcaps_dir() << " is missing"; \
      GTEST_SKIP() << ::saloam::testing::ouster_pcaps_dir() << " is missing (the real Ouster captures)"; \
    }                                                                                               \
  } while (false)
