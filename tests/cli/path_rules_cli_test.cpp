// End-to-end: every command's paths go through one rule (core/path_rules.hpp):
// an output never equals, holds or lies inside an input, and a folder that a
// run replaces whole never holds another of its outputs. Each refusal exits
// 2 naming both paths, and leaves every file as it was (issue #39).

#include <gtest/gtest.h>

#include <fstream>
#include <map>

#include "cli/cli_fixture.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;
using namespace testing;

/// Every path under `root` with its bytes (a folder: empty), links as their target.
std::map<std::string, std::string> snapshot(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator(); ++it) {
    const std::string name = fs::relative(it->path(), root).string();
    if (it->is_symlink()) {
      files[name] = "-> " + fs::read_symlink(it->path()).string();
    } else if (it->is_regular_file()) {
      files[name] = file_text(it->path());
    } else {
      files[name] = "";
    }
  }
  return files;
}

struct Case {
  std::string args;                   ///< saloam's arguments ({} replaced by the temporary folder)
  std::string output, other;          ///< the two paths the message must name (relative to it)
};

class PathRulesCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("saloam_path_rules");
    const fs::path d = dir_->path();
    write_street_sequence(d / "seq", 4);
    std::string output;
    ASSERT_EQ(run_command(saloam_cmd(fmt::format("slam {} --out {} --no-map --save-map {}", quoted(d / "seq"),
                                                 quoted(d / "run"), quoted(d / "map"))),
                          &output),
              0)
        << output;
    // A map holding a sequence and another map; a folder of labels; a link to the ground truth.
    fs::copy(d / "map", d / "nest", fs::copy_options::recursive);
    fs::copy(d / "seq", d / "nest/seq", fs::copy_options::recursive);
    fs::copy(d / "map", d / "nest/inner", fs::copy_options::recursive);
    fs::copy(d / "map", d / "map2", fs::copy_options::recursive);
    fs::copy(d / "seq/labels", d / "labels", fs::copy_options::recursive);
    fs::create_symlink(d / "seq/poses.txt", d / "link.txt");
  }
  static void TearDownTestSuite() { delete dir_; }
  static TempDir* dir_;
};
TempDir* PathRulesCli::dir_ = nullptr;

TEST_F(PathRulesCli, EveryCommandRefusesAnOutputOverAnInput) {
  const fs::path d = dir_->path();
  const std::vector<Case> cases = {
      // slam: --out, --save-map against SEQ, --labels, --map and each other
      {"slam seq --out seq", "seq", "seq"},
      {"slam seq --out seq/out", "seq/out", "seq"},
      {"slam seq --out map/run --save-map map", "map", "map/run"},
      {"slam nest/seq --out run2 --save-map nest", "nest", "nest/seq"},
      {"slam seq --out run2 --map map --save-map map", "map", "map"},
      {"slam seq --out run2 --map map --save-map map/new", "map/new", "map"},
      {"slam seq --out run2 --map nest/inner --save-map nest", "nest", "nest/inner"},
      {"slam seq --out labels --labels labels", "labels", "labels"},
      {"slam seq --out run2 --save-map seq/../seq", "seq/../seq", "seq"},
      {"slam seq --out run2 --save-map run2", "run2", "run2"},
      // localize: --out against SEQ and --map
      {"localize seq --map map --out map", "map", "map"},
      {"localize seq --map map --out map/loc", "map/loc", "map"},
      {"localize nest/seq --map map2 --out nest", "nest", "nest/seq"},
      // merge: --out against both maps
      {"merge nest/inner map2 --out nest", "nest", "nest/inner"},
      {"merge map map2 --out map2", "map2", "map2"},
      {"merge map map2 --out map/merged", "map/merged", "map"},
      // eval: --json and --plot against --gt, --est, --calib, --map and each other
      {"eval --map map --gt seq --json map/map.json", "map/map.json", "map"},
      {"eval --map map --gt seq --json seq/poses.txt", "seq/poses.txt", "seq"},
      {"eval --gt seq/poses.txt --est run/poses.txt --json link.txt", "link.txt", "seq/poses.txt"},
      {"eval --gt seq/poses.txt --est run/poses.txt --plot run/../run/poses.txt", "run/../run/poses.txt",
       "run/poses.txt"},
      {"eval --gt seq/poses.txt --est run/poses_tum.txt --calib seq/calib.txt --json seq/calib.txt", "seq/calib.txt",
       "seq/calib.txt"},
      {"eval --gt seq/poses.txt --est run/poses.txt --json e.json --plot e.json", "e.json", "e.json"},
      // segment: --out against SEQ and --truth
      {"segment seq --out labels --truth labels", "labels", "labels"},
      {"segment seq --out seq/labels", "seq/labels", "seq"},
      // odom, convert, render, graph, place-eval, simulate, view
      {"odom seq --out seq", "seq", "seq"},
      {"odom nest/seq --out nest", "nest", "nest/seq"},
      {"odom seq --out run2 --labels run2/labels", "run2", "run2/labels"},
      {"convert seq --to pcd --out seq/pcd", "seq/pcd", "seq"},
      {"render seq --out seq", "seq", "seq"},
      {"graph seq --frame 0 --out seq/poses.txt", "seq/poses.txt", "seq"},
      {"place-eval seq --method scancontext --out seq", "seq", "seq"},
      {"simulate --trajectory seq/poses.txt --calib seq/calib.txt --out seq", "seq", "seq/poses.txt"},
      {"view map --out map/view.html", "map/view.html", "map"},
      {"view run --sequence seq --out seq/view.html", "seq/view.html", "seq"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const auto before = snapshot(d);
    // Every word that names something under the folder becomes its absolute path.
    std::string full;
    std::istringstream words(c.args);
    for (std::string word; words >> word;) {
      const bool path = word.find('/') != std::string::npos || fs::exists(d / word) || word == "run2" || word == "e.json";
      full += ' ';
      full += path && word[0] != '-' ? quoted(d / word) : word;
    }
    const std::string output = failure_of(full);
    expect_has(output, (d / c.output).string());
    expect_has(output, (d / c.other).string());
    EXPECT_EQ(snapshot(d), before) << "a refused command changed a file";
  }
}

// The trainers (libtorch builds): a run's folder never holds or lies inside
// its recipe, its starting model or what the recipe's sources read.
TEST_F(PathRulesCli, TrainersRefuseAnOutputOverTheirData) {
#ifndef SALOAM_HAVE_TORCH
  GTEST_SKIP() << "built without libtorch: no trainers";
#else
  const fs::path d = dir_->path() / "train";
  fs::create_directories(d / "run");
  const fs::path seq = dir_->path() / "seq";
  const std::string recipe = fmt::format("train: [{{folder: {}}}]\nvalidation: [{{folder: {}}}]\n", seq.string(), seq.string());
  std::ofstream(d / "recipe.yaml") << recipe;
  std::ofstream(d / "run/recipe.yaml") << recipe;
  const fs::path init = fs::path(SALOAM_TEST_SOURCE_DIR) / "models/segmenter/saloam.yaml";
  struct PathCase {
    std::string args;
    fs::path output, other;
  };
  const std::vector<PathCase> cases = {
      {fmt::format("segment-train --data {} --out {}", quoted(d / "recipe.yaml"), quoted(seq)), seq, seq},
      {fmt::format("segment-train --data {} --out {}", quoted(d / "recipe.yaml"), quoted(seq / "run")), seq / "run", seq},
      {fmt::format("segment-train --data {} --out {}", quoted(d / "run/recipe.yaml"), quoted(d / "run")), d / "run",
       d / "run/recipe.yaml"},
      {fmt::format("segment-train --data {} --init {} --out {}", quoted(d / "recipe.yaml"), quoted(init),
                   quoted(init.parent_path())),
       init.parent_path(), init},
      {fmt::format("sgpr-train --data {} --out {}", quoted(d / "recipe.yaml"), quoted(seq / "run")), seq / "run", seq},
  };
  for (const PathCase& c : cases) {
    SCOPED_TRACE(c.args);
    const auto before = snapshot(dir_->path());
    const std::string output = failure_of(c.args);
    expect_has(output, c.output.string());
    expect_has(output, c.other.string());
    EXPECT_EQ(snapshot(dir_->path()), before) << "a refused command changed a file";
  }
#endif
}

TEST_F(PathRulesCli, NamesThatOnlyShareAPrefixAreSeparate) {
  const fs::path d = dir_->path();
  std::string output;
  ASSERT_EQ(run_command(saloam_cmd(fmt::format("eval --gt {} --est {} --json {}", quoted(d / "seq/poses.txt"),
                                               quoted(d / "run/poses.txt"), quoted(d / "seq.json"))),
                        &output),
            0)
      << output;
  EXPECT_TRUE(fs::exists(d / "seq.json"));
  fs::remove(d / "seq.json");
}

}  // namespace
}  // namespace saloam
