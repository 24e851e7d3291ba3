// End-to-end: `saloam simulate --passes`, `saloam slam --save-map` and
// `saloam localize` on two short passes of one simulated world.

#include <cmath>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.hpp"

namespace saloam {
namespace {

using namespace testing;

TEST(LocalizeCli, SavesAMapAndLocalisesASecondPassInIt) {
  TempDir dir("saloam_localize_cli");
  std::string output;
  for (const int pass : {0, 1}) {
    ASSERT_EQ(run_command(saloam_cmd(fmt::format("simulate --preset straight --passes 0:120,30:200 --pass {} --beams 16 "
                                                 "--labels noisy --out {}",
                                                 pass, quoted(dir / fmt::format("pass{}", pass)))),
                          &output),
              0)
        << output;
  }
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {} --no-map --save-map {}", quoted(dir / "pass0"),
                                               quoted(dir / "slam"), quoted(dir / "map"))),
                        &output),
            0)
      << output;
  EXPECT_NE(output.find("saved map: "), std::string::npos) << output;
  for (const char* file : {"map.json", "config.yaml", "keyframes.bin", "edges.bin", "places.bin", "features/000000.bin"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "map" / file)) << file;
  }
  const auto slam_summary = nlohmann::json::parse(file_text(dir / "slam" / "summary.json"));
  EXPECT_GT(slam_summary["saved_map"]["bytes"].get<double>(), 0);

  ASSERT_EQ(run_command(saloam_cmd(fmt::format("localize {} --map {} --out {}", quoted(dir / "pass1"), quoted(dir / "map"),
                                               quoted(dir / "loc"))),
                        &output),
            0)
      << output;
  EXPECT_NE(output.find("judged against the truth"), std::string::npos) << output;
  const auto summary = nlohmann::json::parse(file_text(dir / "loc" / "summary.json"));
  ASSERT_TRUE(summary.contains("first_placed_after_m")) << summary.dump(1);
  EXPECT_LT(summary["first_placed_after_m"].get<double>(), 20.0);
  EXPECT_EQ(summary["false_relocalizations"].get<int>(), 0);
  EXPECT_LT(summary["localized_rmse_in_map_m"].get<double>(), 0.3);
  // Beside it the map's own error where those frames are (their nearest
  // keyframes'), which they inherit: the localisation adds a few cm at most.
  ASSERT_TRUE(summary.contains("map_error_where_localized_m")) << summary.dump(1);
  const double map_error = summary["map_error_where_localized_m"].get<double>();
  EXPECT_GT(map_error, 0.0);
  EXPECT_LT(summary["localized_rmse_in_map_m"].get<double>() - map_error, 0.1) << summary.dump(1);
  EXPECT_NE(output.find("the map's own error where the frames were localized"), std::string::npos) << output;
  // Pass 1 drives 80 poses beyond the mapped stretch: it leaves the map and says so.
  EXPECT_GE(summary["left_mapped_area"].get<int>(), 1);
  EXPECT_GT(summary["odometry"].get<int>(), 0);
  // One pose line per placed frame; frames.csv lists every frame.
  const std::size_t placed = summary["localized"].get<std::size_t>() + summary["odometry"].get<std::size_t>();
  EXPECT_EQ(line_count(dir / "loc" / "poses.txt"), placed);
  EXPECT_EQ(line_count(dir / "loc" / "frames.csv"), summary["frames"].get<std::size_t>() + 1);
  // frames.csv's error column measures what the summary measures (after the
  // map's own error is aligned away): its localized rows give the same RMSE.
  std::istringstream frames(file_text(dir / "loc" / "frames.csv"));
  std::string row;
  std::getline(frames, row);
  ASSERT_EQ(row.substr(row.rfind(',') + 1), "error_m") << row;
  double squares = 0;
  std::size_t localized = 0;
  while (std::getline(frames, row)) {
    if (row.find(",localized,") == std::string::npos) continue;
    const double e = std::stod(row.substr(row.rfind(',') + 1));
    squares += e * e;
    ++localized;
  }
  ASSERT_EQ(localized, summary["localized"].get<std::size_t>());
  EXPECT_NEAR(std::sqrt(squares / static_cast<double>(localized)), summary["localized_rmse_in_map_m"].get<double>(), 1e-4);

  // A folder that is not a map is refused, naming its manifest.
  std::filesystem::create_directories(dir / "not_a_map");
  EXPECT_EQ(run_command(saloam_cmd(fmt::format("localize {} --map {} --out {}", quoted(dir / "pass1"),
                                               quoted(dir / "not_a_map"), quoted(dir / "loc2"))),
                        &output),
            2)
      << output;
  EXPECT_NE(output.find("map.json"), std::string::npos) << output;
  // --save-map never replaces a folder that is not a map.
  EXPECT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {} --no-map --save-map {}", quoted(dir / "pass0"),
                                               quoted(dir / "slam2"), quoted(dir / "pass1"))),
                        &output),
            2)
      << output;
  EXPECT_NE(output.find("is not a saloam map"), std::string::npos) << output;
}

}  // namespace
}  // namespace saloam
