// JSON, Markdown and plot output of a trajectory evaluation.

#include "saloam/eval/evaluation_report.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

/// A loop in the ground plane of the given axes, ~1.2 km long.
std::vector<Pose> loop_path(int ground_a, int ground_b, std::size_t frames = 1200) {
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < frames; ++i) {
    const double phi = 2.0 * M_PI * static_cast<double>(i) / static_cast<double>(frames);
    Pose T = Pose::Identity();
    T.translation()[ground_a] = 200.0 * std::sin(phi);
    T.translation()[ground_b] = 150.0 * (1.0 - std::cos(phi));
    poses.push_back(T);
  }
  return poses;
}

std::vector<Pose> drifted(const std::vector<Pose>& gt) {
  std::vector<Pose> est = gt;
  for (std::size_t i = 0; i < est.size(); ++i) est[i].translation() *= 1.0 + 0.03 * std::sin(0.01 * static_cast<double>(i));
  return est;
}

bool is_png(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  return in && std::string(magic + 1, 3) == "PNG";
}

TEST(EvaluationJson, HoldsTheDocumentedKeys) {
  const auto gt = loop_path(0, 2);
  const auto est = drifted(gt);
  const auto ev = evaluate_trajectories(gt, est);
  const auto j = evaluation_to_json(ev, {"gt.txt", "est.txt"});

  EXPECT_EQ(j.at("gt"), "gt.txt");
  EXPECT_EQ(j.at("est"), "est.txt");
  EXPECT_EQ(j.at("num_poses"), 1200);
  EXPECT_EQ(j.at("alignment"), "se3");
  EXPECT_DOUBLE_EQ(j.at("kitti").at("t_err_percent").get<double>(), ev.kitti.t_err_percent);
  EXPECT_DOUBLE_EQ(j.at("kitti").at("r_err_deg_per_100m").get<double>(), ev.kitti.r_err_deg_per_100m);
  ASSERT_EQ(j.at("kitti").at("per_length").size(), 8u);
  const auto& first = j.at("kitti").at("per_length").at(0);
  EXPECT_EQ(first.at("length_m"), 100.0);
  EXPECT_EQ(first.at("segments"), ev.kitti.per_length[0].segments);
  EXPECT_DOUBLE_EQ(first.at("t_err_percent").get<double>(), ev.kitti.per_length[0].t_err_percent);
  EXPECT_TRUE(first.contains("r_err_deg_per_100m"));
  for (const char* key : {"rmse_aligned", "mean_aligned", "median_aligned", "max_aligned", "rmse_unaligned",
                          "mean_unaligned", "median_unaligned", "max_unaligned"}) {
    EXPECT_TRUE(j.at("ate").at(key).is_number()) << key;
  }
  EXPECT_DOUBLE_EQ(j.at("ate").at("rmse_aligned").get<double>(), ev.ate.aligned.rmse);
  EXPECT_DOUBLE_EQ(j.at("ate").at("rmse_unaligned").get<double>(), ev.ate.unaligned.rmse);
  EXPECT_DOUBLE_EQ(j.at("rpe").at("trans_rmse_m").get<double>(), ev.rpe.trans_rmse_m);
  EXPECT_DOUBLE_EQ(j.at("rpe").at("rot_rmse_deg").get<double>(), ev.rpe.rot_rmse_deg);
  EXPECT_EQ(j.at("ate").at("per_pose_aligned_m").size(), 1200u);
  EXPECT_EQ(j.at("rpe").at("per_frame_trans_m").size(), 1199u);
  EXPECT_EQ(j.at("rpe").at("per_frame_rot_deg").size(), 1199u);
  EXPECT_TRUE(j.at("warnings").empty());
  const auto& bias = j.at("scale_bias");
  EXPECT_EQ(bias.at("delta"), 10);
  EXPECT_EQ(bias.at("windows"), ev.bias.windows);
  EXPECT_DOUBLE_EQ(bias.at("length_m").get<double>(), ev.bias.length_m);
  EXPECT_DOUBLE_EQ(bias.at("forward_percent").get<double>(), ev.bias.forward_percent);
  EXPECT_DOUBLE_EQ(bias.at("lateral_percent").get<double>(), ev.bias.lateral_percent);
  EXPECT_DOUBLE_EQ(bias.at("vertical_percent").get<double>(), ev.bias.vertical_percent);
  EXPECT_EQ(bias.at("body_up").size(), 3u);
  const auto& axes = j.at("ate").at("per_axis_rmse");
  EXPECT_DOUBLE_EQ(axes.at("sideways_m").get<double>(), ev.ate_axes.sideways_m);
  EXPECT_DOUBLE_EQ(axes.at("vertical_m").get<double>(), ev.ate_axes.vertical_m);
  EXPECT_DOUBLE_EQ(axes.at("forward_m").get<double>(), ev.ate_axes.forward_m);

  const auto compact = evaluation_to_json(ev, {}, false);
  EXPECT_FALSE(compact.at("ate").contains("per_pose_aligned_m"));
  EXPECT_FALSE(compact.at("rpe").contains("per_frame_trans_m"));
}

TEST(EvaluationJson, UndefinedValuesAreNullAndFileRoundTrips) {
  const auto gt = loop_path(0, 1, 40);  // far shorter than 100 m
  std::vector<Pose> gt_short(gt.begin(), gt.begin() + 20);
  for (auto& T : gt_short) T.translation() *= 0.1;
  const std::vector<Pose> est(gt_short.begin(), gt_short.begin() + 15);
  const auto ev = evaluate_trajectories(gt_short, est);

  testing::TempDir dir;
  write_evaluation_json(dir / "sub" / "eval.json", ev, {"a", "b"});
  std::ifstream in(dir / "sub" / "eval.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_TRUE(j.at("kitti").at("t_err_percent").is_null());
  EXPECT_TRUE(j.at("kitti").at("per_length").at(0).at("r_err_deg_per_100m").is_null());
  EXPECT_EQ(j.at("kitti").at("segments"), 0);
  EXPECT_EQ(j.at("num_poses"), 15);
  EXPECT_EQ(j.at("gt_poses"), 20);
  EXPECT_EQ(j.at("warnings").size(), 2u);  // length mismatch + no KITTI segment
}

TEST(EvaluationJson, UnwritablePathIsAnInputError) {
  testing::TempDir dir;
  std::ofstream(dir / "file") << "x";
  const auto gt = loop_path(0, 1, 50);
  const auto ev = evaluate_trajectories(gt, gt);
  // A path below a regular file cannot be created.
  EXPECT_THROW(write_evaluation_json(dir / "file" / "eval.json", ev), InputError);
}

TEST(EvaluationMarkdown, ShowsHeadlineAndPerLengthTables) {
  const auto gt = loop_path(0, 2);
  const auto ev = evaluate_trajectories(gt, drifted(gt));
  std::ostringstream out;
  print_evaluation_markdown(out, ev, {"00.txt", "est.txt"});
  const std::string text = out.str();
  EXPECT_NE(text.find("est.txt vs 00.txt"), std::string::npos);
  EXPECT_NE(text.find("| KITTI translation error | "), std::string::npos);
  EXPECT_NE(text.find("| ATE RMSE, se3-aligned | "), std::string::npos);
  EXPECT_NE(text.find("| ATE RMSE, unaligned | "), std::string::npos);
  EXPECT_NE(text.find("| RPE (1-frame) translation RMSE | "), std::string::npos);
  EXPECT_NE(text.find(fmt::format("| ATE RMSE sideways / vertical / forward (sensor frame), se3-aligned | {:.4f} / ",
                                  ev.ate_axes.sideways_m)),
            std::string::npos)
      << text;
  EXPECT_NE(text.find(fmt::format("| scale bias forward / lateral / vertical (10-frame) | {:.4f} / ",
                                  ev.bias.forward_percent)),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("| segment length [m] | t_err [%] | r_err [deg/100 m] | segments |"), std::string::npos);
  EXPECT_NE(text.find("| 800 | "), std::string::npos);
  EXPECT_NE(text.find(fmt::format("{:.6f}", ev.ate.aligned.rmse)), std::string::npos);
  EXPECT_EQ(text.find("warning"), std::string::npos);
}

TEST(EvaluationMarkdown, WithoutAlignmentOnlyUnalignedRows) {
  const auto gt = loop_path(0, 2);
  EvaluationOptions options;
  options.alignment = Alignment::kNone;
  const auto ev = evaluate_trajectories(gt, drifted(gt), options);
  std::ostringstream out;
  print_evaluation_markdown(out, ev);
  EXPECT_EQ(out.str().find("-aligned"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("| ATE RMSE, unaligned | "), std::string::npos);
}

TEST(EvaluationMarkdown, ShortPathShowsNotAvailableAndWarning) {
  const auto gt = loop_path(0, 1, 30);
  std::vector<Pose> small = gt;
  for (auto& T : small) T.translation() *= 0.05;
  const auto ev = evaluate_trajectories(small, small);
  std::ostringstream out;
  print_evaluation_markdown(out, ev);
  EXPECT_NE(out.str().find("| KITTI translation error | n/a % |"), std::string::npos);
  EXPECT_NE(out.str().find("> warning: "), std::string::npos);
}

TEST(TopDownAxes, PicksTheGroundPlane) {
  EXPECT_EQ(top_down_axes(loop_path(0, 2)), std::make_pair(0, 2));  // KITTI camera frame: x-z
  EXPECT_EQ(top_down_axes(loop_path(0, 1)), std::make_pair(0, 1));  // LiDAR frame: x-y
  EXPECT_EQ(top_down_axes(loop_path(2, 1)), std::make_pair(1, 2));
  EXPECT_EQ(top_down_axes({}), std::make_pair(0, 1));
  EXPECT_EQ(top_down_axes(std::vector<Pose>(5, Pose::Identity())), std::make_pair(0, 1));
}

TEST(EvaluationPlot, WritesPngForBothFrameConventions) {
  testing::TempDir dir;
  for (const auto& [a, b] : {std::pair{0, 2}, std::pair{0, 1}}) {
    const auto gt = loop_path(a, b);
    const auto est = drifted(gt);
    const auto ev = evaluate_trajectories(gt, est);
    const auto file = dir / fmt::format("plot_{}{}.png", a, b);
    plot_evaluation(file, gt, est, ev, {"gt", "est"});
    ASSERT_TRUE(std::filesystem::exists(file));
    EXPECT_GT(std::filesystem::file_size(file), 10000u);
    EXPECT_TRUE(is_png(file));
  }
}

TEST(EvaluationPlot, HandlesDegenerateTrajectories) {
  testing::TempDir dir;
  const std::vector<Pose> still(10, Pose::Identity());
  const auto ev = evaluate_trajectories(still, still);
  plot_evaluation(dir / "still.png", still, still, ev);
  EXPECT_TRUE(is_png(dir / "still.png"));
}

}  // namespace
}  // namespace saloam
