// End-to-end: `saloam sgpr-train` on a tiny simulated recipe (with libtorch),
// or its message when built without libtorch.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "saloam/place/sgpr_network.hpp"
#include "cli/cli_fixture.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using namespace testing;

#ifdef SALOAM_HAVE_TORCH

TEST(SgprTrainCli, TrainsOnASimulatedRecipeAndResumes) {
  TempDir dir;
  {
    std::ofstream recipe(dir / "recipe.yaml");
    recipe << "defaults: {frame_step: 2, labels: gt}\n"
              "train:\n  - {simulate: 'preset:urban-loop', frames: '0:16', seed: 3}\n"
              "validation:\n  - {simulate: 'preset:urban-loop', frames: '0:12', seed: 4}\n";
  }
  const fs::path out = dir / "run";
  const std::string base = saloam_cmd("-q sgpr-train --data ") + quoted(dir / "recipe.yaml") +
                           " --batch 4 --pairs-per-epoch 8 --seed 2";
  std::string output;
  ASSERT_EQ(run_command(base + " --epochs 1 --out " + quoted(out), &output), 0) << output;
  EXPECT_NE(output.find("epoch   1/1: loss"), std::string::npos) << output;
  for (const char* f : {"best.sgw", "model.sgw", "training.json", "curves.png", "recipe.yaml", "checkpoint/state.json"})
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  EXPECT_NO_THROW((void)SgprNetwork::load(out / "model.sgw"));  // what is trained runs on the Eigen inference
  // A second run into the same folder is refused; --resume continues it (graphs from the cache).
  EXPECT_NE(run_command(base + " --epochs 2 --out " + quoted(out), &output), 0);
  EXPECT_NE(output.find("--resume"), std::string::npos) << output;
  ASSERT_EQ(run_command(saloam_cmd("-q sgpr-train --batch 4 --pairs-per-epoch 8 --seed 2 --epochs 2 --resume ") +
                            quoted(out),
                        &output),
            0)
      << output;
  EXPECT_NE(output.find("epoch   2/2: loss"), std::string::npos) << output;
  EXPECT_EQ(output.find("epoch   1/2"), std::string::npos) << output;
  // Options left out take the run's own; options that differ are refused.
  ASSERT_EQ(run_command(saloam_cmd("-q sgpr-train --epochs 3 --resume ") + quoted(out), &output), 0) << output;
  EXPECT_NE(output.find("epoch   3/3: loss"), std::string::npos) << output;
  EXPECT_NE(run_command(saloam_cmd("-q sgpr-train --epochs 4 --batch 8 --resume ") + quoted(out), &output), 0);
  EXPECT_NE(output.find("options differ"), std::string::npos) << output;
}

TEST(SgprTrainCli, BadRecipeNamesTheFile) {
  TempDir dir;
  std::ofstream(dir / "recipe.yaml") << "train: [{simulate: missing.txt}]\nvalidation: [{folder: nowhere}]\n";
  std::string output;
  EXPECT_NE(run_command(saloam_cmd("sgpr-train --data ") + quoted(dir / "recipe.yaml") + " --out " +
                            quoted(dir / "run"),
                        &output),
            0);
  EXPECT_NE(output.find("recipe.yaml"), std::string::npos) << output;
}

#else

TEST(SgprTrainCli, SaysItWasBuiltWithoutLibtorch) {
  TempDir dir;
  expect_needs_libtorch("sgpr-train --data x.yaml --out " + quoted(dir / "run"));
}

#endif

}  // namespace
}  // namespace saloam
