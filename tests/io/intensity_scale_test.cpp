// The intensity range of a source (io/intensity_scale.hpp): by the field's
// type where it tells, by the first scan's values otherwise, robust to a few
// stray values, and the --intensity-scale override.
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "saloam/core/error.hpp"
#include "saloam/io/intensity_scale.hpp"

namespace saloam {
namespace {

/// n values spread evenly over [0, top].
std::vector<float> spread(std::size_t n, float top) {
  std::vector<float> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = top * static_cast<float>(i) / static_cast<float>(n - 1);
  return v;
}

TEST(IntensityScale, FloatValuesTellTheirRange) {
  EXPECT_EQ(choose_intensity_scale(std::nullopt, ScalarType::kFloat32, spread(1000, 0.99F)).divisor, 1.0F);
  EXPECT_EQ(choose_intensity_scale(std::nullopt, ScalarType::kFloat32, spread(1000, 1.4F)).divisor, 1.0F);
  EXPECT_EQ(choose_intensity_scale(std::nullopt, ScalarType::kFloat32, spread(1000, 87.0F)).divisor, 255.0F);
  EXPECT_EQ(choose_intensity_scale(std::nullopt, ScalarType::kFloat64, spread(1000, 255.0F)).divisor, 255.0F);
  EXPECT_EQ(choose_intensity_scale(std::nullopt, ScalarType::kFloat32, spread(1000, 3000.0F)).divisor, 65535.0F);
  // Integer types other than uint8 and uint16 say nothing of the range either.
  EXPECT_EQ(choose_intensity_scale(std::nullopt, ScalarType::kUint32, spread(1000, 200.0F)).divisor, 255.0F);
  EXPECT_EQ(choose_intensity_scale(std::nullopt, ScalarType::kInt16, spread(1000, 0.0F)).divisor, 1.0F);

  const IntensityScale found =
      choose_intensity_scale(std::nullopt, ScalarType::kFloat32, std::vector<float>(1000, 200.0F));
  EXPECT_EQ(found.describe(), "0-255, divided by 255 (detected: float32 field, peak 200 in the first scan "
                              "(--intensity-scale to choose))");
}

TEST(IntensityScale, AFewStrayValuesDoNotChangeTheRange) {
  std::vector<float> values = spread(2000, 0.9F);
  values[10] = 250.0F;  // three stray returns of a 0..1 scan
  values[500] = 180.0F;
  values[1999] = 3000.0F;
  values[7] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(choose_intensity_scale(std::nullopt, ScalarType::kFloat32, values).divisor, 1.0F);
  EXPECT_LE(intensity_peak(values), 0.9F);
  // But a 0..255 scan with dark points only here and there is 0..255.
  std::vector<float> dark(2000, 0.5F);
  for (std::size_t i = 0; i < dark.size(); i += 100) dark[i] = 40.0F;
  EXPECT_EQ(choose_intensity_scale(std::nullopt, ScalarType::kFloat32, dark).divisor, 255.0F);
}

TEST(IntensityScale, IntegerFieldsAreScaledByTheirType) {
  const IntensityScale u8 = choose_intensity_scale(std::nullopt, ScalarType::kUint8, spread(100, 0.0F));
  EXPECT_EQ(u8.divisor, 255.0F);  // even for a dark first scan
  EXPECT_EQ(u8.describe(), "0-255, divided by 255 (uint8 field)");
  EXPECT_EQ(choose_intensity_scale(std::nullopt, ScalarType::kUint16, spread(100, 4000.0F)).divisor, 65535.0F);
  // A uint16 field whose values stay within 0..255 holds 8-bit values.
  const IntensityScale u16 = choose_intensity_scale(std::nullopt, ScalarType::kUint16, spread(100, 250.0F));
  EXPECT_EQ(u16.divisor, 255.0F);
  EXPECT_NE(u16.how.find("uint16 field, its values within 0-255"), std::string::npos) << u16.how;
}

TEST(IntensityScale, TheGivenScaleWins) {
  const IntensityScale given = choose_intensity_scale(255.0F, ScalarType::kFloat32, spread(100, 0.9F));
  EXPECT_EQ(given.divisor, 255.0F);
  EXPECT_EQ(given.describe(), "0-255, divided by 255 (as given (--intensity-scale 255))");
  EXPECT_EQ(choose_intensity_scale(1.0F, ScalarType::kUint8, spread(100, 200.0F)).divisor, 1.0F);
  EXPECT_EQ(unread_intensity_scale(65535.0F).divisor, 65535.0F);
  EXPECT_EQ(unread_intensity_scale(std::nullopt).divisor, 1.0F);
  EXPECT_EQ(choose_intensity_scale(std::nullopt, std::nullopt, {}).describe(),
            "0-1, kept (no intensity field: remission 0)");
}

TEST(IntensityScale, ParsesTheOptionAndNamesABadValue) {
  EXPECT_EQ(parse_intensity_scale("auto"), std::nullopt);
  EXPECT_EQ(parse_intensity_scale("1"), 1.0F);
  EXPECT_EQ(parse_intensity_scale("255"), 255.0F);
  EXPECT_EQ(parse_intensity_scale("65535"), 65535.0F);
  try {
    (void)parse_intensity_scale("100");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "--intensity-scale 100: not one of auto, 1, 255, 65535");
  }
}

TEST(IntensityScale, ApplyDividesEveryRemission) {
  LabelledCloud cloud;
  cloud.push_back({1, 0, 0}, 255.0F);
  cloud.push_back({2, 0, 0}, 51.0F);
  IntensityScale{255.0F, ""}.apply(cloud);
  EXPECT_EQ(cloud.remission[0], 1.0F);
  EXPECT_EQ(cloud.remission[1], 51.0F / 255.0F);
  IntensityScale{1.0F, ""}.apply(cloud);
  EXPECT_EQ(cloud.remission[1], 51.0F / 255.0F);
}

}  // namespace
}  // namespace saloam
