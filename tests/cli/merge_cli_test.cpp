// End-to-end: `saloam slam --map` (a second pass joins a saved map) and
// `saloam merge` on two short passes of one simulated world, and `saloam
// eval --map` of the merged map.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.hpp"

namespace saloam {
namespace {

using namespace testing;

TEST(MergeCli, JoinsASecondPassAndMergesTwoMaps) {
  TempDir dir("saloam_merge_cli");
  std::string output;
  for (const int pass : {0, 1}) {
    const std::string name = fmt::format("pass{}", pass);
    ASSERT_EQ(run_command(saloam_cmd(fmt::format("simulate --preset straight --passes 0:120,30:200 --pass {} --beams 16 "
                                                 "--labels noisy --out {}",
                                                 pass, quoted(dir / name))),
                          &output),
              0)
        << output;
    ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {} --no-map --save-map {}", quoted(dir / name),
                                                 quoted(dir / ("slam" + name)), quoted(dir / ("map" + name)))),
                          &output),
              0)
        << output;
  }
  const std::string map_json = file_text(dir / "mappass0" / "map.json");
  // The joined map may not replace the map it joins.
  EXPECT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {} --no-map --map {} --save-map {}", quoted(dir / "pass1"),
                                               quoted(dir / "joined"), quoted(dir / "mappass0"),
                                               quoted(dir / "mappass0"))),
                        &output),
            2)
      << output;
  EXPECT_NE(output.find("an output never replaces an input"), std::string::npos) << output;
  EXPECT_EQ(file_text(dir / "mappass0" / "map.json"), map_json);

  ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {} --no-map --map {} --save-map {}", quoted(dir / "pass1"),
                                               quoted(dir / "joined"), quoted(dir / "mappass0"), quoted(dir / "map01"))),
                        &output),
            0)
      << output;
  EXPECT_NE(output.find("linked to"), std::string::npos) << output;
  const auto summary = nlohmann::json::parse(file_text(dir / "joined" / "summary.json"));
  EXPECT_TRUE(summary["session_join"]["linked"].get<bool>()) << summary.dump(1);
  EXPECT_GT(summary["session_join"]["cross_session_loops"].get<int>(), 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "joined" / "cross_session.csv"));
  const auto joined = nlohmann::json::parse(file_text(dir / "map01" / "map.json"));
  ASSERT_EQ(joined["sessions"].size(), 2u);
  EXPECT_TRUE(joined["sessions"][1]["linked"].get<bool>());
  EXPECT_EQ(file_text(dir / "mappass0" / "map.json"), map_json);  // the input is unchanged
  EXPECT_EQ(line_count(dir / "joined" / "poses.txt"), line_count(dir / "slampass1" / "poses.txt"));

  // Merge refuses to write into an input, then merges the two saved maps.
  EXPECT_EQ(run_command(saloam_cmd(fmt::format("merge {} {} --out {}", quoted(dir / "mappass0"), quoted(dir / "mappass1"),
                                               quoted(dir / "mappass1"))),
                        &output),
            2)
      << output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("merge {} {} --out {}", quoted(dir / "mappass0"), quoted(dir / "mappass1"),
                                               quoted(dir / "merged"))),
                        &output),
            0)
      << output;
  const auto merged = nlohmann::json::parse(file_text(dir / "merged" / "map.json"));
  ASSERT_EQ(merged["sessions"].size(), 2u);
  EXPECT_TRUE(merged["sessions"][1]["linked"].get<bool>());
  EXPECT_EQ(merged["cross_session_loops"], joined["cross_session_loops"]);
  EXPECT_EQ(merged["keyframes"], joined["keyframes"]);

  // Per-session error of the merged map against both passes' truth.
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("eval --map {} --gt {} --gt {} --json {}", quoted(dir / "merged"),
                                               quoted(dir / "pass0"), quoted(dir / "pass1"), quoted(dir / "eval.json"))),
                        &output),
            0)
      << output;
  const auto eval = nlohmann::json::parse(file_text(dir / "eval.json"));
  ASSERT_EQ(eval["sessions"].size(), 2u) << eval.dump(1);
  for (const auto& session : eval["sessions"]) {
    EXPECT_TRUE(session["linked"].get<bool>());
    EXPECT_GT(session["aligned_m"]["count"].get<int>(), 10);
    EXPECT_LT(session["aligned_m"]["rmse"].get<double>(), 0.5) << eval.dump(1);
  }
  EXPECT_EQ(eval["cross_session_loops"]["false"].get<int>(), 0);
  EXPECT_EQ(eval["cross_session_loops"]["true"], merged["cross_session_loops"]);
  // One truth for two sessions, or --est with --map: refused.
  EXPECT_EQ(run_command(saloam_cmd(fmt::format("eval --map {} --gt {}", quoted(dir / "merged"), quoted(dir / "pass0"))),
                        &output),
            2)
      << output;
  EXPECT_NE(output.find("2 sessions, 1 ground truths"), std::string::npos) << output;
  EXPECT_EQ(run_command(saloam_cmd(fmt::format("eval --map {} --gt {} --gt {} --est {}", quoted(dir / "merged"),
                                               quoted(dir / "pass0"), quoted(dir / "pass1"),
                                               quoted(dir / "slampass1" / "poses.txt"))),
                        &output),
            2)
      << output;

  // Localised in the merged map, each frame is set beside the map's own
  // error where it is: every session's keyframes against their own pass's
  // truth (pass 1 drives on beyond pass 0, where only session 1 has keyframes).
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("localize {} --map {} --out {}", quoted(dir / "pass1"),
                                               quoted(dir / "merged"), quoted(dir / "loc"))),
                        &output),
            0)
      << output;
  const auto located = nlohmann::json::parse(file_text(dir / "loc" / "summary.json"));
  EXPECT_EQ(located["false_relocalizations"].get<int>(), 0) << located.dump(1);
  ASSERT_TRUE(located.contains("map_error_where_localized_m")) << located.dump(1);
  EXPECT_LT(located["map_error_where_localized_m"].get<double>(), 0.2) << located.dump(1);
  EXPECT_LT(located["localized_rmse_in_map_m"].get<double>(), 0.3) << located.dump(1);
}

}  // namespace
}  // namespace saloam
