// IMU text files (io/imu_text.hpp): written and read back, and every bad
// line named.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "saloam/io/imu_text.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

std::string error_of(const std::string& text) {
  std::istringstream in(text);
  return testing::input_error_of([&] { (void)read_imu_text(in, "imu.txt"); });
}

TEST(ImuText, RoundTrips) {
  testing::TempDir dir("saloam_imu_text");
  const std::vector<ImuSample> samples{{0.0, {0.1, -0.2, 9.81}, {0.001, 0.002, -0.003}},
                                       {0.0025, {0.15, -0.25, 9.79}, {0.5, -1.25, 3.0}}};
  write_imu_text(dir.path() / "imu.txt", samples, "test");
  const std::vector<ImuSample> read = read_imu_text(dir.path() / "imu.txt");
  ASSERT_EQ(read.size(), 2u);
  EXPECT_DOUBLE_EQ(read[1].time, 0.0025);
  EXPECT_LT((read[1].acceleration - samples[1].acceleration).norm(), 1e-8);
  EXPECT_LT((read[1].angular_velocity - samples[1].angular_velocity).norm(), 1e-8);
}

TEST(ImuText, NamesTheFileAndLineOfEveryBadSample) {
  EXPECT_NE(error_of("# x\n0 0 0 9.8 0 0 0\n0.01 0 0 9.8 0 0\n").find("line 3: expected 7 numbers"), std::string::npos);
  EXPECT_NE(error_of("0 0 0 9.8 0 0 0\n0 0 0 9.8 0 0 0\n").find("line 2"), std::string::npos);
  EXPECT_NE(error_of("0 0 0 nan 0 0 0\n").find("line 1: non-finite"), std::string::npos);
  EXPECT_NE(error_of("0 0 0 9.8 0 0 x\n").find("'x' is not a number"), std::string::npos);
  EXPECT_NE(error_of("# only a comment\n").find("no IMU samples"), std::string::npos);
  EXPECT_NE(error_of("0 0 0 nan 0 0 0\n").find("imu.txt"), std::string::npos);
  EXPECT_EQ(error_of("0 0 0 9.8 0 0 0\n"), "no error");
}

}  // namespace
}  // namespace saloam
