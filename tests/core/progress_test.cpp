#include "saloam/core/progress.hpp"

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

namespace saloam {
namespace {

/// What a bar of 20 items prints on stderr at the given log level.
std::string drawn_at(spdlog::level::level_enum level) {
  const auto before = spdlog::get_level();
  spdlog::set_level(level);
  ::testing::internal::CaptureStderr();
  {
    ProgressBar bar(20, "frames");
    for (int i = 0; i < 20; ++i) bar.advance();
  }
  const std::string text = ::testing::internal::GetCapturedStderr();
  spdlog::set_level(before);
  return text;
}

TEST(ProgressBar, DrawsAtInfoAndStaysQuietBelowIt) {
  const std::string info = drawn_at(spdlog::level::info);
  EXPECT_NE(info.find("frames ["), std::string::npos) << info;
  EXPECT_NE(info.find("20/20"), std::string::npos) << info;
  EXPECT_EQ(drawn_at(spdlog::level::warn), "");  // saloam -q
}

}  // namespace
}  // namespace saloam
