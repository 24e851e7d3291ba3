// End-to-end: `saloam eval` on the real KITTI 00 estimates and on bad files.

#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "testing/test_support.hpp"

namespace saloam {
namespace {

using testing::cli_path;
using testing::run_command;
using testing::shared_file;
using testing::quoted;
using testing::TempDir;

TEST(EvalCli, Kitti00OrbWritesJsonAndPlot) {
  SALOAM_REQUIRE_SHARED_DATA();
  TempDir dir;
  const auto gt = shared_file("data/kitti/poses/00.txt");
  const auto est = shared_file("data/kitti/estimates/KITTI_00_ORB.txt");
  const auto json_file = dir / "orb.json";
  const auto png_file = dir / "orb.png";
  std::string output;
  const int code = run_command(quoted(cli_path()) + " eval --gt " + quoted(gt) + " --est " + quoted(est) +
                                   " --json " + quoted(json_file) + " --plot " + quoted(png_file),
                               &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("| KITTI translation error | 0.69973 % |"), std::string::npos) << output;
  EXPECT_NE(output.find("| ATE RMSE, se3-aligned | 1.303450 m |"), std::string::npos) << output;

  std::ifstream in(json_file);
  ASSERT_TRUE(in) << json_file;
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("num_poses"), 4541);
  EXPECT_EQ(j.at("est"), "KITTI_00_ORB.txt");
  EXPECT_NEAR(j.at("kitti").at("t_err_percent").get<double>(), 0.69973, 2e-3 * 0.69973);
  EXPECT_NEAR(j.at("kitti").at("r_err_deg_per_100m").get<double>(), 0.25333, 2e-3 * 0.25333);
  EXPECT_EQ(j.at("kitti").at("segments"), 3283);
  ASSERT_EQ(j.at("kitti").at("per_length").size(), 8u);
  EXPECT_EQ(j.at("kitti").at("per_length").at(7).at("length_m"), 800.0);
  EXPECT_NEAR(j.at("ate").at("rmse_aligned").get<double>(), 1.303450, 1e-6);
  EXPECT_NEAR(j.at("ate").at("rmse_unaligned").get<double>(), 7.790289, 1e-6);
  for (const char* key : {"mean_aligned", "median_aligned", "max_aligned"}) {
    EXPECT_TRUE(j.at("ate").at(key).is_number()) << key;
  }
  EXPECT_NEAR(j.at("rpe").at("trans_rmse_m").get<double>(), 0.028120, 1e-6);
  EXPECT_TRUE(j.at("rpe").at("rot_rmse_deg").is_number());

  ASSERT_TRUE(std::filesystem::exists(png_file));
  EXPECT_GT(std::filesystem::file_size(png_file), 20000u);
}

TEST(EvalCli, Sim3AlignmentAndShorterEstimate) {
  SALOAM_REQUIRE_SHARED_DATA();
  TempDir dir;
  const auto gt = shared_file("data/kitti/poses/00.txt");
  // An interrupted run: only the first 1000 poses of the S-PTAM estimate.
  std::ifstream in(shared_file("data/kitti/estimates/KITTI_00_SPTAM.txt"));
  std::ofstream out(dir / "short.txt");
  std::string line;
  for (int i = 0; i < 1000 && std::getline(in, line); ++i) out << line << '\n';
  out.close();
  std::string output;
  const int code = run_command(quoted(cli_path()) + " eval --gt " + quoted(gt) + " --est " + quoted(dir / "short.txt") +
                                   " --align sim3 --json " + quoted(dir / "e.json"),
                               &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("evaluating the first 1000 poses"), std::string::npos) << output;
  std::ifstream json_in(dir / "e.json");
  const auto j = nlohmann::json::parse(json_in);
  EXPECT_EQ(j.at("num_poses"), 1000);
  EXPECT_EQ(j.at("gt_poses"), 4541);
  EXPECT_EQ(j.at("alignment"), "sim3");
  EXPECT_GT(j.at("ate").at("scale").get<double>(), 0.9);
  EXPECT_LT(j.at("ate").at("scale").get<double>(), 1.1);
}

// A simulated sequence with poses_sensor.txt beside poses.txt: scoring
// against poses.txt works but says which file holds the scans' poses.
TEST(EvalCli, PointsToTheSensorPosesOfASimulatedSequence) {
  TempDir dir;
  std::ofstream gt(dir / "poses.txt");
  for (int i = 0; i < 30; ++i) gt << "1 0 0 0 0 1 0 0 0 0 1 " << i << "\n";
  gt.close();
  std::filesystem::copy_file(dir / "poses.txt", dir / "est.txt");
  const std::string command =
      quoted(cli_path()) + " eval --gt " + quoted(dir / "poses.txt") + " --est " + quoted(dir / "est.txt");
  std::string output;
  ASSERT_EQ(run_command(command, &output), 0) << output;
  EXPECT_EQ(output.find("poses_sensor.txt"), std::string::npos) << output;
  std::filesystem::copy_file(dir / "poses.txt", dir / "poses_sensor.txt");
  ASSERT_EQ(run_command(command, &output), 0) << output;
  EXPECT_NE(output.find("score an odometry against --gt"), std::string::npos) << output;
}

// Old cases of issue #39: two TUM files are paired by time, not by line;
// sim3 on a ground truth that does not move is refused; a standard output
// that cannot be written (/dev/full) is an error.
TEST(EvalCli, TumFilesArePairedByTimeAndOutputErrorsFail) {
  TempDir dir;
  std::ofstream gt(dir / "gt_tum.txt"), est(dir / "est_tum.txt"), still(dir / "still_tum.txt");
  for (int i = 0; i < 20; ++i) {
    const double x = 1.0 * i, y = 0.05 * i * i;
    gt << fmt::format("{:.9f} {} {} 0 0 0 0 1\n", 100.0 + 0.1 * i, x, y);
    still << fmt::format("{:.9f} 0 0 0 0 0 0 1\n", 100.0 + 0.1 * i);
    // The estimate: poses 5..14 only, stamped 3 ms late.
    if (i >= 5 && i < 15) est << fmt::format("{:.9f} {} {} 0 0 0 0 1\n", 100.003 + 0.1 * i, x, y);
  }
  gt.close();
  est.close();
  still.close();
  const std::string eval = quoted(cli_path()) + " eval --gt " + quoted(dir / "gt_tum.txt") + " --est " +
                           quoted(dir / "est_tum.txt");
  std::string output;
  ASSERT_EQ(run_command(eval + " --json " + quoted(dir / "e.json"), &output), 0) << output;
  std::ifstream json_in(dir / "e.json");
  const auto j = nlohmann::json::parse(json_in);
  EXPECT_EQ(j.at("num_poses"), 10);
  EXPECT_LT(j.at("ate").at("rmse_aligned").get<double>(), 1e-6) << j.dump();
  // Static ground truth with sim3: refused, not a scale of 0 and an ATE of 0.
  EXPECT_NE(run_command(quoted(cli_path()) + " eval --gt " + quoted(dir / "still_tum.txt") + " --est " +
                            quoted(dir / "gt_tum.txt") + " --align sim3",
                        &output),
            0);
  EXPECT_NE(output.find("the ground truth does not move"), std::string::npos) << output;
  // Standard output on a full device.
  EXPECT_NE(run_command(eval + " > /dev/full", &output), 0) << output;
}

TEST(EvalCli, MalformedPoseFileNamesFileAndLine) {
  SALOAM_REQUIRE_SHARED_DATA();
  TempDir dir;
  const auto bad = dir / "bad_poses.txt";
  {
    std::ifstream in(shared_file("data/kitti/estimates/KITTI_00_ORB.txt"));
    std::ofstream out(bad);
    std::string line;
    for (int i = 0; i < 5 && std::getline(in, line); ++i) out << line << '\n';
    out << "1 0 0 0 0 1 0 0 0 0 1 oops\n";  // line 6
  }
  std::string output;
  const int code = run_command(quoted(cli_path()) + " eval --gt " + quoted(shared_file("data/kitti/poses/00.txt")) +
                                   " --est " + quoted(bad),
                               &output);
  EXPECT_NE(code, 0) << output;
  EXPECT_NE(output.find(bad.string()), std::string::npos) << output;
  EXPECT_NE(output.find("line 6"), std::string::npos) << output;
}

TEST(EvalCli, MissingFileAndBadAlignmentFail) {
  SALOAM_REQUIRE_SHARED_DATA();
  TempDir dir;
  std::string output;
  int code = run_command(quoted(cli_path()) + " eval --gt " + quoted(dir / "nope.txt") + " --est " +
                             quoted(shared_file("data/kitti/estimates/KITTI_00_ORB.txt")),
                         &output);
  EXPECT_NE(code, 0) << output;
  EXPECT_NE(output.find("nope.txt"), std::string::npos) << output;

  code = run_command(quoted(cli_path()) + " eval --gt " + quoted(shared_file("data/kitti/poses/00.txt")) + " --est " +
                         quoted(shared_file("data/kitti/estimates/KITTI_00_ORB.txt")) + " --align affine",
                     &output);
  EXPECT_NE(code, 0) << output;
  EXPECT_NE(output.find("--align"), std::string::npos) << output;
}

}  // namespace
}  // namespace saloam
