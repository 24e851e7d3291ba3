#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "saloam/viz/canvas.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

bool is_png(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  return std::string(magic + 1, 3) == "PNG";
}

TEST(Canvas, PlotMapsDataToPixelsWithEqualAspect) {
  Plot plot(800, 600);
  plot.set_range(0, 100, 0, 10, /*equal_aspect=*/true);
  const auto a = plot.to_pixel({0, 0});
  const auto b = plot.to_pixel({10, 0});
  const auto c = plot.to_pixel({0, 10});
  EXPECT_NEAR((b - a).norm(), (c - a).norm(), 1e-9);  // 10 m is 10 m both ways
  EXPECT_LT(c.y(), a.y());                            // y grows upwards
}

TEST(Canvas, WritesPngFiles) {
  testing::TempDir dir;
  Plot plot(400, 300);
  std::vector<Eigen::Vector2d> pts{{0, 0}, {1, 1}, {2, 0}};
  plot.fit_range(pts, false);
  plot.line(pts, {0, 0, 0});
  plot.colored_line(pts, {0.0, 0.5, 1.0}, 0.0, 1.0);
  plot.legend({{"gt", {0, 0, 0}}});
  plot.colorbar(0, 1, "error [m]");
  plot.set_title("test");
  plot.save_png(dir / "plot.png");
  EXPECT_TRUE(is_png(dir / "plot.png"));

  RasterImage img(10, 4, {1, 2, 3});
  img.set(3, 2, {255, 0, 0});
  img.set(-1, 99, {0, 255, 0});  // outside: ignored
  EXPECT_EQ(img.get(3, 2), (Rgb{255, 0, 0}));
  EXPECT_EQ(img.get(0, 0), (Rgb{1, 2, 3}));
  img.save_png(dir / "img.png", 2, 3);
  EXPECT_TRUE(is_png(dir / "img.png"));
}

TEST(Canvas, ColourMapsAreOrderedAndClamped) {
  EXPECT_EQ(viridis(-1.0), viridis(0.0));
  EXPECT_EQ(viridis(2.0), viridis(1.0));
  EXPECT_LT(turbo(0.0).r, turbo(0.8).r);
  EXPECT_EQ(turbo(std::nan("")), turbo(0.0));
}

}  // namespace
}  // namespace saloam
