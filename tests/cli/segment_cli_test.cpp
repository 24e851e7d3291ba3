// End-to-end: `saloam segment-train` trains a tiny SegNet on a simulated
// recipe, `saloam segment` writes its labels (scored against the truth) and
// `odom --segmenter` runs on them in-process (with libtorch); without
// libtorch both say that segmentation was not built.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "saloam/io/scan_io.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using testing::cli_path;
using testing::quoted;
using testing::run_command;
using testing::TempDir;

/// A simulated 16-beam sequence of the urban loop (noisy labels, truth in labels_gt).
fs::path simulate(const TempDir& dir) {
  const fs::path seq = dir / "seq";
  std::string output;
  EXPECT_EQ(run_command(quoted(cli_path()) + " -q simulate --preset urban-loop --frames 0:6 --beams 16 --labels noisy --out " +
                            quoted(seq),
                        &output),
            0)
      << output;
  return seq;
}

#ifdef SALOAM_HAVE_TORCH

TEST(SegmentCli, TrainsLabelsScoresAndRunsInProcess) {
  TempDir dir;
  std::ofstream(dir / "recipe.yaml") << "defaults: {frame_step: 20, beams: 16}\n"
                                        "train: [{simulate: 'preset:urban-loop', frames: '0:60', seed: 3}]\n"
                                        "validation: [{simulate: 'preset:urban-loop', frames: '0:40', seed: 4}]\n";
  std::string output;
  ASSERT_EQ(run_command(quoted(cli_path()) + " -q segment-train --data " + quoted(dir / "recipe.yaml") +
                            " --out " + quoted(dir / "model") +
                            " --epochs 1 --samples-per-epoch 4 --batch 2 --widths 4,8,8 --stem-stride 2 --columns 512",
                        &output),
            0)
      << output;
  for (const char* f : {"best.yaml", "best.pt", "model.yaml", "training.json", "curves.png", "recipe.yaml"})
    EXPECT_TRUE(fs::is_regular_file(dir / "model" / f)) << f;

  const fs::path seq = simulate(dir);
  const std::string model = " --segmenter " + quoted(dir / "model" / "best.yaml");
  ASSERT_EQ(run_command(quoted(cli_path()) + " segment " + quoted(seq) + " --out " + quoted(dir / "pred") + model, &output), 0)
      << output;
  EXPECT_NE(output.find("against " + (seq / "labels_gt").string() + ": mIoU"), std::string::npos) << output;
  for (int i = 0; i < 6; ++i) {
    const auto labels = read_label_file(dir / "pred" / ("00000" + std::to_string(i) + ".label"));
    EXPECT_EQ(labels.size(), read_scan(seq / "velodyne" / ("00000" + std::to_string(i) + ".bin")).size());
  }
  EXPECT_TRUE(fs::is_regular_file(dir / "pred" / "segment_000003.png"));
  // Never over an input.
  EXPECT_NE(run_command(quoted(cli_path()) + " segment " + quoted(seq) + " --out " + quoted(seq / "labels") + model, &output), 0);
  EXPECT_NE(output.find("labels folder"), std::string::npos) << output;

  // In-process, the stage's time in timing.json; --segment with --labels or --no-semantics is refused.
  ASSERT_EQ(run_command(quoted(cli_path()) + " -q odom " + quoted(seq) + " --out " + quoted(dir / "odom") + model, &output), 0)
      << output;
  std::ifstream timing(dir / "odom" / "timing.json");
  const std::string text((std::istreambuf_iterator<char>(timing)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"segmentation\""), std::string::npos) << text;
  EXPECT_NE(run_command(quoted(cli_path()) + " odom " + quoted(seq) + " --out " + quoted(dir / "o2") + model +
                            " --no-semantics",
                        &output),
            0);
  EXPECT_NE(output.find("does not use labels"), std::string::npos) << output;
  EXPECT_NE(run_command(quoted(cli_path()) + " odom " + quoted(seq) + " --out " + quoted(dir / "o3") + model + " --labels " +
                            quoted(dir / "pred"),
                        &output),
            0);
  EXPECT_NE(output.find("not both"), std::string::npos) << output;
}

TEST(SegmentCli, AModelThatIsNotThereIsNamed) {
  TempDir dir;
  const fs::path seq = simulate(dir);
  std::string output;
  EXPECT_NE(run_command(quoted(cli_path()) + " segment " + quoted(seq) + " --out " + quoted(dir / "pred") +
                            " --segmenter " + quoted(dir / "missing.yaml"),
                        &output),
            0);
  EXPECT_NE(output.find("missing.yaml: segmentation model description not found"), std::string::npos) << output;
  EXPECT_NE(run_command(quoted(cli_path()) + " segment " + quoted(seq) + " --out " + quoted(dir / "pred") +
                            " --segmenter " + quoted(dir / "net.pt"),
                        &output),
            0);
  EXPECT_NE(output.find("--projection"), std::string::npos) << output;
}

#else

TEST(SegmentCli, SaysItWasBuiltWithoutLibtorch) {
  TempDir dir;
  std::string output;
  EXPECT_NE(run_command(quoted(cli_path()) + " segment-train --data x.yaml --out " + quoted(dir / "run"), &output), 0);
  EXPECT_NE(output.find("built without libtorch"), std::string::npos) << output;
  std::ofstream(dir / "m.yaml") << "format: saloam-segmenter 1\n"
                                   "network: {type: torchscript, file: m.pt}\n"
                                   "projection: {rows: 64, fov_up_deg: 3.0, fov_down_deg: -25.0, columns: 1024,\n"
                                   "  channels: [range], means: [0], stds: [1]}\n"
                                   "classes: semantickitti\nknn: {k: 5, window: 5, cutoff: 1.0, sigma: 1.0}\n";
  std::ofstream(dir / "m.pt") << "x";
  const fs::path seq = simulate(dir);
  EXPECT_NE(run_command(quoted(cli_path()) + " segment " + quoted(seq) + " --out " + quoted(dir / "pred") +
                            " --segmenter " + quoted(dir / "m.yaml"),
                        &output),
            0);
  EXPECT_NE(output.find("built only with libtorch"), std::string::npos) << output;
}

#endif

}  // namespace
}  // namespace saloam
