#include "saloam/core/path_rules.hpp"

#include <cstdlib>
#include <fstream>

#include <gtest/gtest.h>

#include "saloam/core/error.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

std::string breach(const PathRules& rules) {
  try {
    rules.check();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PathRules, ComparesByComponentsNotByText) {
  EXPECT_TRUE(path_within("/a/b/c", "/a/b"));
  EXPECT_TRUE(path_within("/a/b", "/a/b"));
  EXPECT_FALSE(path_within("/a/bc", "/a/b"));
  EXPECT_FALSE(path_within("/a", "/a/b"));
  EXPECT_EQ(comparable_path("/a/b/../c/./d/"), fs::path("/a/c/d"));
}

TEST(PathRules, RefusesAnOutputEqualToHoldingOrInsideAnInput) {
  testing::TempDir tmp;
  const fs::path seq = tmp / "seq";
  fs::create_directories(seq);
  EXPECT_NE(breach(PathRules().input("SEQ", seq).output("--out", tmp / "x/../seq", OutputUse::kFolder)).find("is the input SEQ"),
            std::string::npos);
  const std::string inside = breach(PathRules().input("SEQ", seq).output("--json", seq / "a.json"));
  EXPECT_NE(inside.find("lies inside the input SEQ " + seq.string()), std::string::npos) << inside;
  EXPECT_NE(inside.find((seq / "a.json").string()), std::string::npos) << inside;
  EXPECT_NE(breach(PathRules().input("SEQ", seq).output("--save-map", tmp.path(), OutputUse::kReplacedFolder))
                .find("holds the input SEQ"),
            std::string::npos);
  EXPECT_EQ(breach(PathRules().input("SEQ", seq).output("--out", tmp / "seq2", OutputUse::kFolder)), "");
  EXPECT_EQ(breach(PathRules().input("SEQ", "").output("--out", "", OutputUse::kFolder)), "");
}

TEST(PathRules, FollowsLinksAndHardLinks) {
  testing::TempDir tmp;
  fs::create_directories(tmp / "seq");
  { std::ofstream(tmp / "seq/poses.txt") << "1\n"; }
  fs::create_directory_symlink(tmp / "seq", tmp / "alias");
  fs::create_hard_link(tmp / "seq/poses.txt", tmp / "hard.txt");
  EXPECT_NE(breach(PathRules().input("SEQ", tmp / "seq").output("--out", tmp / "alias/run", OutputUse::kFolder)), "");
  EXPECT_NE(breach(PathRules().input("--gt", tmp / "seq/poses.txt").output("--json", tmp / "hard.txt")), "");
  // A link after a missing folder and `..` (found by the path_rules fuzz
  // harness): creating new/ and going up from it reaches the link, so the
  // output is the input's folder.
  EXPECT_NE(breach(PathRules().input("SEQ", tmp / "seq/velodyne").output("--out", tmp / "new/../alias",
                                                                          OutputUse::kReplacedFolder)),
            "");
  EXPECT_NE(breach(PathRules().input("SEQ", tmp / "new/../alias/../seq").output("--out", tmp / "seq/run",
                                                                                OutputUse::kFolder)),
            "");
  EXPECT_EQ(breach(PathRules().input("SEQ", tmp / "seq").output("--out", tmp / "alias/../run", OutputUse::kFolder)),
            "");
}

// Issue #53: a bind mount of a folder is that folder under another path,
// which no comparison of paths sees (same device and inode). Needs the
// right to mount (root in a container that allows it): skipped otherwise.
TEST(PathRules, ABindMountOfAnInputIsTheInput) {
  testing::TempDir tmp;
  fs::create_directories(tmp / "map/seq");
  fs::create_directories(tmp / "view");
  const std::string mount = "mount --bind '" + (tmp / "map").string() + "' '" + (tmp / "view").string() + "' 2>/dev/null";
  if (std::system(mount.c_str()) != 0) GTEST_SKIP() << "no right to bind-mount here";
  const std::string a = breach(PathRules().input("SEQ", tmp / "view/seq").output("--save-map", tmp / "map",
                                                                                  OutputUse::kReplacedFolder));
  const std::string b = breach(PathRules().input("--map", tmp / "map").output("--out", tmp / "view/run",
                                                                             OutputUse::kFolder));
  const std::string c = breach(PathRules().input("SEQ", tmp / "elsewhere").output("--out", tmp / "view/run",
                                                                                 OutputUse::kFolder));
  const std::string unmount = "umount '" + (tmp / "view").string() + "'";
  EXPECT_EQ(std::system(unmount.c_str()), 0);
  EXPECT_NE(a.find("holds the input SEQ"), std::string::npos) << a;
  EXPECT_NE(b.find("lies inside the input --map"), std::string::npos) << b;
  EXPECT_EQ(c, "");
}

TEST(PathRules, AReplacedFolderNeverHoldsAnotherOutput) {
  const std::string message = breach(
      PathRules().output("--out", "/m/run", OutputUse::kFolder).output("--save-map", "/m", OutputUse::kReplacedFolder));
  EXPECT_NE(message.find("--save-map /m holds the output --out /m/run"), std::string::npos) << message;
  // A folder that is added to may hold a replaced one.
  EXPECT_EQ(breach(PathRules().output("--out", "/o", OutputUse::kFolder).output("--save-map", "/o/map",
                                                                                OutputUse::kReplacedFolder)),
            "");
  EXPECT_NE(breach(PathRules().output("--json", "/e.json").output("--plot", "/x/../e.json")), "");
}

}  // namespace
}  // namespace saloam
