// End-to-end tests of `saloam sgpr-score`, `saloam graph` and `saloam place-eval`.

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <random>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/sequence.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

using testing::quoted;

std::string saloam_cmd(const std::string& args) { return quoted(testing::cli_path()) + " " + args; }

TEST(LoopCli, SgprScoreReproducesTheReferencePair) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto dir = testing::shared_dir() / "models/sgpr";
  std::string output;
  const int rc = testing::run_command(
      saloam_cmd(fmt::format("sgpr-score --model {} {} {} {}", quoted(dir / "sgpr_kitti.sgw"), quoted(dir / "graph_0.json"),
                             quoted(dir / "graph_3.json"), quoted(dir / "graph_250.json"))),
      &output);
  ASSERT_EQ(rc, 0) << output;
  EXPECT_NE(output.find("graph_3.json score 0.997977"), std::string::npos) << output;
  EXPECT_NE(output.find("graph_250.json score 0.000001"), std::string::npos) << output;
  // The model through the configuration; order matters (3-0 = 0.98185).
  ASSERT_EQ(testing::run_command(saloam_cmd(fmt::format("sgpr-score --set loop.sgpr_model={} {} {}",
                                                        (dir / "sgpr_kitti.sgw").string(), quoted(dir / "graph_3.json"),
                                                        quoted(dir / "graph_0.json"))),
                                 &output),
            0)
      << output;
  EXPECT_NE(output.find("score 0.981845"), std::string::npos) << output;
}

TEST(LoopCli, WithoutAModelSaysHowToPassOne) {
  // Nothing is read from ../shared at run time: no weights given and none
  // shipped is an error that names the options.
  testing::TempDir tmp;
  std::ofstream(tmp / "graph.json") << "{}";
  std::string output;
  EXPECT_NE(testing::run_command("SALOAM_DATA_DIR=" + quoted(tmp.path()) + " " +
                                     saloam_cmd(fmt::format("sgpr-score {} {}", quoted(tmp / "graph.json"),
                                                            quoted(tmp / "graph.json"))),
                                 &output),
            0);
  EXPECT_NE(output.find("--model FILE.sgw"), std::string::npos) << output;
  EXPECT_NE(output.find("loop.sgpr_model"), std::string::npos) << output;
}

TEST(LoopCli, BadModelFilesGiveClearErrors) {
  SALOAM_REQUIRE_SHARED_DATA();
  testing::TempDir tmp;
  const auto graph = testing::shared_dir() / "models/sgpr/graph_0.json";
  std::ofstream(tmp / "garbage.sgw") << "this is not a weights file";
  std::string output;
  EXPECT_EQ(testing::run_command(saloam_cmd(fmt::format("sgpr-score --model {} {} {}", quoted(tmp / "garbage.sgw"),
                                                        quoted(graph), quoted(graph))),
                                 &output),
            2);
  EXPECT_NE(output.find("garbage.sgw"), std::string::npos) << output;
  EXPECT_NE(output.find("not an SGPR weights file"), std::string::npos) << output;
  EXPECT_EQ(testing::run_command(saloam_cmd(fmt::format("sgpr-score --model {} {} {}", quoted(tmp / "missing.sgw"),
                                                        quoted(graph), quoted(graph))),
                                 &output),
            2);
  EXPECT_NE(output.find("missing.sgw: SGPR weights file not found"), std::string::npos) << output;
  // Through the configuration key as well.
  EXPECT_EQ(testing::run_command(saloam_cmd(fmt::format("sgpr-score --set loop.sgpr_model={} {} {}",
                                                        (tmp / "missing.sgw").string(), quoted(graph), quoted(graph))),
                                 &output),
            2);
  EXPECT_NE(output.find("missing.sgw: SGPR weights file not found"), std::string::npos) << output;
}

/// A small synthetic labelled sequence: a street of labelled objects, driven
/// along x for 55 frames, then back to the start (a revisit of frames 0..2).
std::filesystem::path write_revisit_sequence(const testing::TempDir& tmp) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0F, 1.0F);
  LabelledCloud world;
  std::uint16_t instance = 1;
  for (int k = 0; k < 160; ++k) {
    const float x = -40.0F + 1.9F * static_cast<float>(k) + 0.5F * u(rng);
    const float y = (k % 2 ? 1.0F : -1.0F) * (6.0F + 8.0F * (u(rng) + 1.0F));
    const std::uint16_t label = std::array<std::uint16_t, 4>{cls::kPole, cls::kCar, cls::kVegetation, cls::kBuilding}[k % 4];
    const Eigen::Vector3f half = label == cls::kPole ? Eigen::Vector3f(0.05F, 0.05F, 2) : Eigen::Vector3f(1.5F, 1, 1.5F);
    const int count = label == cls::kPole ? 150 : 400;
    for (int i = 0; i < count; ++i)
      world.push_back(Eigen::Vector3f(x, y, 0) + Eigen::Vector3f(u(rng), u(rng), u(rng)).cwiseProduct(half), 0.3F, label,
                      label == cls::kCar ? instance : 0);
    instance += label == cls::kCar;
  }
  const auto root = tmp / "seq";
  SequenceWriter writer(root);
  std::vector<Pose> poses;
  for (int f = 0; f < 58; ++f) {
    Pose pose = Pose::Identity();
    pose.translation() = f < 55 ? Eigen::Vector3d(4.0 * f, 0, 0) : Eigen::Vector3d(0.8 * (f - 55), 0.3, 0);
    poses.push_back(pose);
    LabelledCloud scan;
    scan.has_labels = true;
    const Eigen::Vector3f t = pose.translation().cast<float>();
    for (std::size_t i = 0; i < world.size(); ++i) {
      const Eigen::Vector3f p = world.points[i] - t;
      if (p.head<2>().norm() < 50.0F) scan.push_back(p, world.remission[i], world.label[i], world.instance[i]);
    }
    writer.write_scan(static_cast<std::size_t>(f), scan);
  }
  writer.write_camera_poses(poses);
  writer.write_calib(Pose::Identity());
  return root;
}

// SGPR runs on the shipped model (models/sgpr/saloam.sgw): no --model needed.
TEST(LoopCli, GraphAndPlaceEvalOnASyntheticRevisit) {
  testing::TempDir tmp;
  const auto seq = write_revisit_sequence(tmp);
  std::string output;
  ASSERT_EQ(testing::run_command(saloam_cmd(fmt::format("graph {} --frame 0 --out {}", quoted(seq), quoted(tmp / "g0.json"))),
                                 &output),
            0)
      << output;
  EXPECT_NE(output.find("nodes"), std::string::npos);
  nlohmann::json graph = nlohmann::json::parse(std::ifstream(tmp / "g0.json"));
  EXPECT_GT(graph["nodes"].size(), 10U);
  EXPECT_EQ(graph["nodes"].size(), graph["centers"].size());
  EXPECT_EQ(graph["pose"].size(), 12U);
  EXPECT_EQ(graph["edges"].size(), graph["weights"].size());
  EXPECT_NE(testing::run_command(saloam_cmd(fmt::format("graph {} --frame 999 --out {}", quoted(seq), quoted(tmp / "x.json"))),
                                 &output),
            0);

  for (const std::string method : {"sgpr", "scancontext", "ssc"}) {
    const auto out = tmp / ("eval_" + method);
    ASSERT_EQ(testing::run_command(saloam_cmd(fmt::format("place-eval {} --method {} --out {}", quoted(seq), method,
                                                          quoted(out))),
                                   &output),
              0)
        << output;
    EXPECT_NE(output.find("max F1"), std::string::npos) << output;
    EXPECT_NE(output.find("precision at 100 % recall"), std::string::npos) << output;
    EXPECT_NE(output.find("recall at 100 % precision"), std::string::npos) << output;
    EXPECT_TRUE(std::filesystem::exists(out / "pr_curve.png"));
    std::ifstream csv(out / "pr_curve.csv");
    std::string header;
    std::getline(csv, header);
    EXPECT_EQ(header, "threshold,precision,recall");
    const auto summary = nlohmann::json::parse(std::ifstream(out / "summary.json"));
    // Frames 55..57 are within 3 m of frames 0..1 (exclusion 50 keeps them comparable).
    EXPECT_GE(summary["positive_pairs"].get<int>(), 3) << method;
    EXPECT_GE(summary["negative_pairs"].get<int>(), 5) << method;
    const double f1 = summary["max_f1"].get<double>();
    EXPECT_GT(f1, 0.0) << method;
    EXPECT_LE(f1, 1.0) << method;
  }
  // --graphs: the graphs saved by one run give the same scores without the scans' graphs being rebuilt.
  ASSERT_EQ(testing::run_command(saloam_cmd(fmt::format("place-eval {} --method sgpr --save-graphs --save-scores --out {}",
                                                        quoted(seq), quoted(tmp / "saved"))),
                                 &output),
            0)
      << output;
  ASSERT_EQ(testing::run_command(saloam_cmd(fmt::format("place-eval {} --method sgpr --graphs {} --save-scores --out {}",
                                                        quoted(seq), quoted(tmp / "saved" / "graphs"),
                                                        quoted(tmp / "reused"))),
                                 &output),
            0)
      << output;
  auto text = [](const std::filesystem::path& f) {
    std::ifstream in(f);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(text(tmp / "saved" / "pair_scores.csv"), text(tmp / "reused" / "pair_scores.csv"));
  EXPECT_FALSE(text(tmp / "reused" / "pair_scores.csv").empty());
  EXPECT_NE(testing::run_command(saloam_cmd(fmt::format("place-eval {} --method ssc --graphs {}", quoted(seq),
                                                        quoted(tmp / "saved" / "graphs"))),
                                 &output),
            0);
  EXPECT_NE(output.find("--graphs needs an SGPR method"), std::string::npos) << output;
  // Scan Context sees the same street again: the revisit pairs outrank the far pairs.
  const auto sc = nlohmann::json::parse(std::ifstream(tmp / "eval_scancontext/summary.json"));
  EXPECT_GT(sc["max_f1"].get<double>(), 0.5);
  EXPECT_NE(testing::run_command(saloam_cmd(fmt::format("place-eval {} --method nope", quoted(seq))), &output), 0);
  EXPECT_NE(output.find("nope not in {sgpr,scancontext,hybrid,ssc}"), std::string::npos) << output;
}

// SSC on a short simulated street (16 beams, 8 frames 1.4 m apart): pairs
// within 3 m are matches, beyond 7 m non-matches.
TEST(LoopCli, PlaceEvalSscOnASimulatedStreet) {
  testing::TempDir tmp;
  const auto seq = tmp / "seq";
  std::string output;
  ASSERT_EQ(testing::run_command(saloam_cmd(fmt::format(
                                     "simulate --out {} --beams 16 --azimuth-steps 600 --preset straight --frames 0:16 "
                                     "--stride 2 --labels noisy",
                                     quoted(seq))),
                                 &output),
            0)
      << output;
  const auto out = tmp / "eval";
  ASSERT_EQ(testing::run_command(saloam_cmd(fmt::format("place-eval {} --method ssc --exclude 0 --positive 3 "
                                                        "--negative 7 --out {}",
                                                        quoted(seq), quoted(out))),
                                 &output),
            0)
      << output;
  EXPECT_NE(output.find("semantic scan contexts"), std::string::npos) << output;
  const auto summary = nlohmann::json::parse(std::ifstream(out / "summary.json"));
  EXPECT_EQ(summary["method"].get<std::string>(), "ssc");
  EXPECT_GE(summary["positive_pairs"].get<int>(), 6);
  EXPECT_GE(summary["negative_pairs"].get<int>(), 4);
  EXPECT_GT(summary["max_f1"].get<double>(), 0.5);
  // Without labels SSC has nothing to describe.
  std::filesystem::rename(seq / "labels", tmp / "labels_aside");
  EXPECT_EQ(testing::run_command(saloam_cmd(fmt::format("place-eval {} --method ssc", quoted(seq))), &output), 2);
  EXPECT_NE(output.find("SSC needs semantic labels"), std::string::npos) << output;
}

TEST(LoopCli, PlaceEvalLeavesOutUnreadableFrames) {
  testing::TempDir tmp;
  const auto seq = write_revisit_sequence(tmp);
  std::ofstream(seq / "velodyne" / "000010.bin", std::ios::trunc).close();  // an empty scan
  std::string output;
  ASSERT_EQ(testing::run_command(
                saloam_cmd(fmt::format("place-eval {} --method scancontext --out {}", quoted(seq), quoted(tmp / "e"))),
                &output),
            0)
      << output;
  EXPECT_NE(output.find("000010.bin"), std::string::npos) << output;
  EXPECT_NE(output.find("1 unreadable left out"), std::string::npos) << output;
  const auto summary = nlohmann::json::parse(std::ifstream(tmp / "e/summary.json"));
  EXPECT_EQ(summary["frames_left_out"].get<int>(), 1);
}

// Every option used or refused (issue #39): --model with a detector that has no model.
TEST(LoopCli, AModelForADetectorWithoutOneIsRefused) {
  testing::TempDir tmp;
  const auto seq = write_revisit_sequence(tmp);
  std::ofstream(tmp / "w.sgw") << "x";
  std::string output;
  EXPECT_EQ(testing::run_command(saloam_cmd(fmt::format("place-eval {} --method scancontext --model {} --out {}",
                                                        quoted(seq), quoted(tmp / "w.sgw"), quoted(tmp / "e"))),
                                 &output),
            2)
      << output;
  EXPECT_NE(output.find("w.sgw: the scancontext detector has no model"), std::string::npos) << output;
  EXPECT_EQ(testing::run_command(saloam_cmd(fmt::format("slam {} --detector scancontext --model {} --out {}",
                                                        quoted(seq), quoted(tmp / "w.sgw"), quoted(tmp / "s"))),
                                 &output),
            2)
      << output;
  EXPECT_NE(output.find("w.sgw: the scancontext detector has no model"), std::string::npos) << output;
  EXPECT_FALSE(std::filesystem::exists(tmp / "s" / "poses.txt"));
}

TEST(LoopCli, PlaceEvalRejectsInconsistentDistances) {
  testing::TempDir tmp;  // checked before the sequence is read: no data needed
  std::string output;
  EXPECT_EQ(testing::run_command(saloam_cmd(fmt::format("place-eval {} --positive 30 --negative 20", quoted(tmp.path()))),
                                 &output),
            2);
  EXPECT_NE(output.find("--positive 30 must be less than --negative 20"), std::string::npos) << output;
  EXPECT_NE(testing::run_command(saloam_cmd(fmt::format("place-eval {} --positive -3", quoted(tmp.path()))), &output), 0);
  EXPECT_NE(output.find("--positive"), std::string::npos) << output;
}

}  // namespace
}  // namespace saloam
