#include <gtest/gtest.h>

#include "saloam/core/error.hpp"
#include "saloam/core/frame_range.hpp"

namespace saloam {
namespace {

TEST(FrameRange, ParsesEveryForm) {
  EXPECT_EQ(FrameRange::parse("").clip(10), (std::pair<std::size_t, std::size_t>{0, 10}));
  EXPECT_EQ(FrameRange::parse("2:5").clip(10), (std::pair<std::size_t, std::size_t>{2, 5}));
  EXPECT_EQ(FrameRange::parse("3:").clip(10), (std::pair<std::size_t, std::size_t>{3, 10}));
  EXPECT_EQ(FrameRange::parse(":4").clip(10), (std::pair<std::size_t, std::size_t>{0, 4}));
  EXPECT_EQ(FrameRange::parse("7").clip(10), (std::pair<std::size_t, std::size_t>{7, 8}));
  EXPECT_EQ(FrameRange::parse("5:100").clip(10), (std::pair<std::size_t, std::size_t>{5, 10}));
}

TEST(FrameRange, RejectsBadRanges) {
  EXPECT_THROW(FrameRange::parse("a:b"), ConfigError);
  EXPECT_THROW(FrameRange::parse("5:5"), ConfigError);
  EXPECT_THROW(FrameRange::parse("-1:3"), ConfigError);
  EXPECT_THROW(FrameRange::parse("1:2:3"), ConfigError);
  EXPECT_THROW((void)FrameRange::parse("20:").clip(10), ConfigError);
  try {
    FrameRange::parse("x", "--frames");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("--frames 'x'"), std::string::npos);
  }
}

}  // namespace
}  // namespace saloam
