#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "saloam/core/config.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

TEST(Config, TableOneDefaults) {
  const SaloamConfig c;
  EXPECT_DOUBLE_EQ(c.odometry.features.alpha, 0.1);
  EXPECT_EQ(c.odometry.features.num_sectors, 6);
  EXPECT_EQ(c.odometry.features.edges_per_sector, 20);
  EXPECT_EQ(c.odometry.features.planars_per_sector, 50);
  EXPECT_EQ(c.odometry.local_map_frames, 40);
  EXPECT_EQ(c.odometry.edge_neighbours, 5);
  EXPECT_EQ(c.odometry.planar_neighbours, 5);
  EXPECT_DOUBLE_EQ(c.odometry.plane_normal_tolerance, 0.05);
  EXPECT_DOUBLE_EQ(c.loop.delta_min, 15.0);
  EXPECT_DOUBLE_EQ(c.loop.delta_max, 100.0);
  EXPECT_EQ(c.loop.num_candidates, 64);
  EXPECT_DOUBLE_EQ(c.loop.zeta, 0.95);
  EXPECT_EQ(c.loop.num_loop, 5);
  EXPECT_DOUBLE_EQ(c.loop.delta_r, 100.0);
  EXPECT_DOUBLE_EQ(c.loop.sigma, 0.01);  // Table I has 0.05 (an odometry drifting ~1 %; config/paper.yaml)
}

TEST(Config, YamlRoundTripIsIdentity) {
  SaloamConfig c;
  apply_config_override(c, "odometry.features.alpha=0.25");
  apply_config_override(c, "odometry.class_weight.pole=3");
  apply_config_override(c, "loop.sgpr_model=/tmp/x.sgw");
  const std::string yaml = config_to_yaml(c);
  SaloamConfig back;
  apply_config_yaml(back, yaml, "roundtrip");
  EXPECT_EQ(config_to_yaml(back), yaml);
  EXPECT_DOUBLE_EQ(back.odometry.features.alpha, 0.25);
  EXPECT_DOUBLE_EQ(back.odometry.class_weight.at("pole"), 3.0);
  EXPECT_EQ(back.loop.sgpr_model, "/tmp/x.sgw");
}

// The shipped config/saloam.yaml documents every key with its default.
TEST(Config, ShippedFileHoldsTheDefaults) {
  const auto loaded = load_config(testing::source_dir() / "config" / "saloam.yaml");
  EXPECT_EQ(config_to_yaml(loaded), config_to_yaml(SaloamConfig{}))
      << "regenerate it with: build/saloam config > config/saloam.yaml";
}

// config/real_kitti.yaml changes only the pose instant (real KITTI: mid-sweep).
TEST(Config, ShippedRealKittiFileSetsMidSweepPoses) {
  const auto loaded = load_config(testing::source_dir() / "config" / "real_kitti.yaml");
  EXPECT_DOUBLE_EQ(loaded.odometry.features.pose_time_in_sweep, 0.05);
  SaloamConfig expected;
  expected.odometry.features.pose_time_in_sweep = 0.05;
  EXPECT_EQ(config_to_yaml(loaded), config_to_yaml(expected));
}

// config/paper.yaml: Table I's values (the defaults) and the paper's literal choices.
TEST(Config, ShippedPaperFileSetsThePublishedChoices) {
  const auto loaded = load_config(testing::source_dir() / "config" / "paper.yaml");
  SaloamConfig expected;
  expected.odometry.local_map_frames = 20;
  expected.odometry.local_map_point = "newest";
  expected.odometry.match_class_groups = false;
  expected.odometry.adaptive_class_weights = false;
  expected.odometry.class_weight["vegetation"] = 1.0;
  expected.odometry.features.ground_edge_alpha = 0.1;
  expected.odometry.features.thin_object_axes = false;
  expected.loop.acceptance = "loss";
  expected.loop.sigma = 0.05;
  EXPECT_EQ(config_to_yaml(loaded), config_to_yaml(expected));
  EXPECT_EQ(loaded.odometry.local_map_frames, 20);  // N_m of Table I
  for (const auto& [name, weight] : loaded.odometry.class_weight) EXPECT_EQ(weight, 1.0) << name;  // "defined equally"
}

TEST(Config, InfinityRoundTrips) {
  SaloamConfig c;
  apply_config_override(c, "odometry.features.ground_edge_alpha=.inf");
  EXPECT_TRUE(std::isinf(c.odometry.features.ground_edge_alpha));
  testing::TempDir dir;
  const auto file = dir.path() / "inf.yaml";
  std::ofstream(file) << config_to_yaml(c);
  EXPECT_TRUE(std::isinf(load_config(file).odometry.features.ground_edge_alpha));
}

TEST(Config, OverridesByShortAndLongName) {
  SaloamConfig c;
  apply_config_override(c, "alpha=0.3");
  EXPECT_DOUBLE_EQ(c.odometry.features.alpha, 0.3);
  apply_config_override(c, "zeta=0.9");
  EXPECT_DOUBLE_EQ(c.loop.zeta, 0.9);
  apply_config_override(c, "odometry.use_semantics=false");
  EXPECT_FALSE(c.odometry.use_semantics);
  apply_config_override(c, "odometry.class_voxel_size={road: 1.5, pole: 0.05}");
  EXPECT_DOUBLE_EQ(c.odometry.class_voxel_size.at("road"), 1.5);
  EXPECT_DOUBLE_EQ(c.odometry.class_voxel_size.at("pole"), 0.05);
  EXPECT_DOUBLE_EQ(class_value(c.odometry.class_voxel_size, cls::kRoad, 0.0), 1.5);
  EXPECT_DOUBLE_EQ(class_value(c.odometry.class_voxel_size, cls::kCar, 0.0), 0.4);  // default entry
  EXPECT_DOUBLE_EQ(class_value(c.odometry.class_weight, cls::kMovingCar, 0.0), 1.0);
}

TEST(Config, ErrorsNameTheProblem) {
  SaloamConfig c;
  auto expect_error = [&](const std::string& assignment, const std::string& fragment) {
    try {
      apply_config_override(c, assignment);
      FAIL() << "no error for " << assignment;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect_error("nonsense=1", "unknown configuration key 'nonsense'");
  expect_error("odometry.alpha_typo=1", "unknown configuration key");
  expect_error("alpha=abc", "wrong type");
  expect_error("alpha", "expected key=value");
  expect_error("odometry.class_weight.spaceship=2", "unknown class 'spaceship'");

  try {
    apply_config_yaml(c, "odometry:\n  local_map_frames: [1, 2]\n", "test.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("test.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("odometry.local_map_frames"), std::string::npos);
  }
  EXPECT_THROW(apply_config_yaml(c, "odometry: {\n", "broken.yaml"), ConfigError);
  EXPECT_THROW(load_config("/nonexistent/saloam.yaml"), InputError);
}

// yaml-cpp keeps both entries of a repeated key; which one wins is not what
// the user meant, so a repeated key, a repeated section and a second document
// are errors naming the file, the key and both lines; so is a key that is
// not a name.
TEST(Config, RepeatedKeysSectionsAndDocumentsAreErrors) {
  auto yaml_error = [](const std::string& text) -> std::string {
    SaloamConfig c;
    try {
      apply_config_yaml(c, text, "twice.yaml");
    } catch (const ConfigError& e) {
      EXPECT_EQ(c.odometry.threads, SaloamConfig{}.odometry.threads) << "the config changed on an error";
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(yaml_error("odometry:\n  threads: 2\n  threads: 3\n"),
            "twice.yaml: 'odometry.threads' is given twice (lines 2 and 3): give each key once");
  EXPECT_EQ(yaml_error("odometry:\n  threads: 2\nloop:\n  sigma: 0.02\nodometry:\n  deskew: false\n"),
            "twice.yaml: 'odometry' is given twice (lines 1 and 5): give each key once");
  EXPECT_EQ(yaml_error("odometry:\n  class_weight:\n    pole: 2\n    pole: 3\n"),
            "twice.yaml: 'odometry.class_weight.pole' is given twice (lines 3 and 4): give each key once");
  EXPECT_EQ(yaml_error("odometry:\n  threads: 2\n---\nodometry:\n  threads: 3\n"),
            "twice.yaml: holds 2 YAML documents (separated by '---'); a configuration is one");
  // A list or a map where a key belongs (found by fuzz_config) names nothing.
  EXPECT_EQ(yaml_error("odometry:\n  class_voxel_size:\n    default: 0.4\n  ? pole: 0.1\n    trunk: 0.1\n"),
            "twice.yaml: line 4: a key in 'odometry' that is not a name (a list or a map)");
  EXPECT_EQ(yaml_error("odometry:\n  class_weight:\n    ? [pole, trunk]\n    : 2\n"),
            "twice.yaml: line 3: a key in 'odometry.class_weight' that is not a name (a list or a map)");
  EXPECT_EQ(yaml_error("? {odometry: 1}\n: 2\n"), "twice.yaml: line 1: a key that is not a name (a list or a map)");
  // One document, with or without its markers, and an empty file are fine.
  EXPECT_EQ(yaml_error("---\nodometry:\n  threads: 2\n...\n"), "no error");
  EXPECT_EQ(yaml_error(""), "no error");
}

// A configuration is read only from a regular file of bounded size: a device
// or a FIFO in its place is refused at once, never read without end or waited on.
TEST(Config, OnlyRegularFilesAreRead) {
  EXPECT_NE(testing::input_error_of([] { (void)load_config("/dev/zero"); }).find("/dev/zero: is not a regular file"),
            std::string::npos);
  testing::TempDir dir;
  const auto fifo = dir / "fifo.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(testing::input_error_of([&] { (void)load_config(fifo); }).find("fifo.yaml: is not a regular file"),
            std::string::npos);
  EXPECT_NE(testing::input_error_of([&] { (void)load_config(dir.path()); }).find("is a directory"), std::string::npos);
  {
    std::ofstream big(dir / "big.yaml");
    big << "# " << std::string(kMaxConfigBytes, 'x') << "\n";
  }
  EXPECT_NE(testing::input_error_of([&] { (void)load_config(dir / "big.yaml"); }).find("more than a configuration file"),
            std::string::npos);
}

// ---- Valid ranges (issue 13: no silently wrong results) ----

// The message of the ConfigError that `apply` throws; fails the test when none is thrown.
template <class Apply>
std::string config_error(Apply&& apply) {
  try {
    apply();
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no ConfigError";
  return "";
}

std::string override_error(const std::string& assignment) {
  SaloamConfig c;
  return config_error([&] { apply_config_override(c, assignment); });
}

// A command-line option bound to a key goes through the same checks as --set.
TEST(Config, BoundOptionsAreCheckedLikeSet) {
  SaloamConfig c;
  const std::string error = config_error([&] { apply_config_option(c, "--threads", "odometry.threads", "-1"); });
  EXPECT_EQ(error.rfind("--threads -1: ", 0), 0U) << error;
  EXPECT_NE(error.find("odometry.threads"), std::string::npos) << error;
  EXPECT_EQ(c.odometry.threads, SaloamConfig{}.odometry.threads);
  EXPECT_NE(config_error([&] { apply_config_option(c, "--threads", "odometry.threads", "two"); }).find("wrong type"),
            std::string::npos);
  apply_config_option(c, "--threads", "odometry.threads", "3");
  EXPECT_EQ(c.odometry.threads, 3);
}

// Finite values just outside a declared range, as --set text.
std::vector<std::string> outside(const Range& r) {
  std::vector<std::string> values;
  if (std::isfinite(r.lo)) values.push_back(fmt::format("{}", r.lo - 1));
  if (std::isfinite(r.hi)) values.push_back(fmt::format("{}", r.hi + 1));
  return values;
}
std::vector<std::string> outside(const AtLeast& r) { return {fmt::format("{}", r.lo - 1)}; }
std::vector<std::string> outside(const Above& r) { return {fmt::format("{}", r.lo)}; }
std::vector<std::string> outside(const OneOf<const char*>&) { return {"nope"}; }
std::vector<std::string> outside(const Any&) { return {}; }

bool admits_infinity(const Range& r) { return std::isinf(r.hi); }
template <class R>
bool admits_infinity(const R&) {
  return false;
}

// Every field with a range, through --set: a value outside it, NaN and (unless
// the range ends at .inf) infinity for real numbers are errors naming the
// origin and the key; the config is unchanged.
TEST(ConfigRanges, EveryFieldRejectsValuesOutsideItsRangeAndNaN) {
  SaloamConfig fields;
  std::vector<std::pair<std::string, std::string>> bad;  // key, value
  visit_sections(fields, [&](std::string_view section, auto& s) {
    visit_fields(s, [&](std::string_view name, auto& member, std::string_view, const auto&... range) {
      using T = std::remove_cvref_t<decltype(member)>;
      if constexpr (sizeof...(range) == 1) {
        std::string key = fmt::format("{}.{}", section, name);
        if constexpr (std::is_same_v<T, ClassValueMap>) key += ".pole";
        const std::size_t before = bad.size();
        // A list field takes its values in a list.
        const auto listed = [](const std::string& v) { return std::is_same_v<T, std::vector<double>> ? "[" + v + "]" : v; };
        for (const auto& value : outside(range...)) bad.emplace_back(key, listed(value));
        if constexpr (std::is_floating_point_v<T> || std::is_same_v<T, ClassValueMap> ||
                      std::is_same_v<T, std::vector<double>>) {
          bad.emplace_back(key, listed(".nan"));
          if (!(admits_infinity(range) && ...)) bad.emplace_back(key, listed(".inf"));
        }
        if constexpr (!(std::is_same_v<std::remove_cvref_t<decltype(range)>, Any> && ...)) {
          EXPECT_GT(bad.size(), before) << key << ": no invalid value to try";
        }
      }
    });
  });
  EXPECT_GE(bad.size(), 100u);  // today 52 fields with a range, most of them real numbers
  const std::string defaults = config_to_yaml(SaloamConfig{});
  for (const auto& [key, value] : bad) {
    SaloamConfig c;
    const std::string assignment = key + "=" + value;
    const std::string message = config_error([&] { apply_config_override(c, assignment); });
    EXPECT_NE(message.find("--set " + assignment + ": '" + key + "'"), std::string::npos) << message;
    EXPECT_NE(message.find("(valid: "), std::string::npos) << message;
    EXPECT_EQ(config_to_yaml(c), defaults) << assignment;
  }
}

// A list of numbers (the sensor's laser elevations) in YAML files and --set.
TEST(Config, ListFieldsReadWriteAndCheckEveryValue) {
  SaloamConfig c;
  apply_config_override(c, "odometry.features.beam_elevations_deg=[2, -0.5, -24.9]");
  EXPECT_EQ(c.odometry.features.beam_elevations_deg, (std::vector<double>{2, -0.5, -24.9}));
  const std::string yaml = config_to_yaml(c);
  EXPECT_NE(yaml.find("beam_elevations_deg: [2, -0.5, -24.9]"), std::string::npos) << yaml;
  SaloamConfig back;
  apply_config_yaml(back, yaml, "saved");
  EXPECT_EQ(back.odometry.features.beam_elevations_deg, c.odometry.features.beam_elevations_deg);
  EXPECT_EQ(override_error("odometry.features.beam_elevations_deg=3"),
            "--set odometry.features.beam_elevations_deg=3: 'odometry.features.beam_elevations_deg' must be a list of "
            "numbers, e.g. [1.5, -2]");
  EXPECT_EQ(override_error("odometry.features.beam_elevations_deg=[1, 95]"),
            "--set odometry.features.beam_elevations_deg=[1, 95]: 'odometry.features.beam_elevations_deg' has 95 at [1], "
            "not allowed (valid: [-90, 90])");
  // num_beams must agree with the list.
  EXPECT_NE(config_error([] {
              SaloamConfig d;
              apply_config_overrides(d, {"odometry.features.beam_elevations_deg=[1, 0]", "odometry.features.num_beams=16"});
            }).find("lists 2 beams"),
            std::string::npos);
}

TEST(ConfigRanges, RepresentativeValuesNameKeyValueAndRange) {
  EXPECT_EQ(override_error("odometry.max_iterations=-5"),
            "--set odometry.max_iterations=-5: 'odometry.max_iterations' = -5 is not allowed (valid: >= 1)");
  EXPECT_EQ(override_error("voxel_size=0"),
            "--set voxel_size=0: 'odometry.voxel_size' = 0 is not allowed (valid: > 0)");
  EXPECT_EQ(override_error("alpha=-1"), "--set alpha=-1: 'odometry.features.alpha' = -1 is not allowed (valid: > 0)");
  EXPECT_EQ(override_error("alpha=.nan"), "--set alpha=.nan: 'odometry.features.alpha' is NaN (valid: > 0)");
  EXPECT_NE(override_error("num_sectors=0").find("'odometry.features.num_sectors' = 0"), std::string::npos);
  EXPECT_NE(override_error("local_map_frames=0").find("(valid: >= 1)"), std::string::npos);
  EXPECT_NE(override_error("sweep_duration=0").find("'odometry.features.sweep_duration' = 0"), std::string::npos);
  EXPECT_NE(override_error("odometry.threads=-1").find("(valid: >= 0)"), std::string::npos);
  EXPECT_NE(override_error("num_beams=2000").find("(valid: [0, 1024])"), std::string::npos);
  EXPECT_EQ(override_error("loop.zeta=1.5"), "--set loop.zeta=1.5: 'loop.zeta' = 1.5 is not allowed (valid: [0, 1])");
  EXPECT_EQ(override_error("loop.detector=nope"),
            "--set loop.detector=nope: 'loop.detector' = 'nope' is not allowed "
            "(valid: one of sgpr, scancontext, hybrid, ssc)");
  EXPECT_NE(override_error("loop.acceptance=strict").find("(valid: one of normalized, loss)"), std::string::npos);
  EXPECT_EQ(override_error("odometry.class_voxel_size.pole=0"),
            "--set odometry.class_voxel_size.pole=0: 'odometry.class_voxel_size.pole' = 0 is not allowed "
            "(valid: > 0)");
  EXPECT_NE(override_error("odometry.class_weight={road: -1}").find("'odometry.class_weight.road' = -1"),
            std::string::npos);
  EXPECT_NE(override_error("loop.seed=-1").find("wrong type"), std::string::npos);
}

TEST(ConfigRanges, BoundsAndDocumentedInfinityAreAccepted) {
  SaloamConfig c;
  for (const char* assignment :
       {"loop.zeta=0", "loop.zeta=1", "odometry.threads=0", "num_beams=16", "odometry.class_weight.pole=0",
        "loop.max_runner_up_ratio=.inf", "odometry.features.ground_edge_alpha=.inf", "loop.detector=hybrid",
        "odometry.features.pose_time_in_sweep=0.1", "loop.delta_min=100", "loop.seed=18446744073709551615"}) {
    EXPECT_NO_THROW(apply_config_override(c, assignment)) << assignment;
  }
  EXPECT_TRUE(std::isinf(c.loop.max_runner_up_ratio));
  EXPECT_EQ(c.loop.detector, "hybrid");
  EXPECT_NE(override_error("loop.max_runner_up_ratio=-.inf").find("(valid: [0, .inf])"), std::string::npos);
  EXPECT_NE(override_error("loop.max_runner_up_ratio=.nan").find("is NaN"), std::string::npos);
}

TEST(ConfigRanges, ContradictingPairsAreRejected) {
  EXPECT_EQ(override_error("odometry.features.min_range=130"),
            "--set odometry.features.min_range=130: 'odometry.features.min_range' = 130 must be less than "
            "'odometry.features.max_range' = 120");
  EXPECT_NE(override_error("max_range=2.5").find("must be less than"), std::string::npos);  // equal is no range
  EXPECT_EQ(override_error("loop.delta_min=200"),
            "--set loop.delta_min=200: 'loop.delta_min' = 200 must not exceed 'loop.delta_max' = 100");
  EXPECT_NE(override_error("loop.delta_max=10").find("'loop.delta_min' = 15 must not exceed"), std::string::npos);
  EXPECT_NE(override_error("pose_time_in_sweep=0.2").find("must lie within the sweep"), std::string::npos);

  // An override that breaks a pair set consistently before is rejected; the other order works.
  SaloamConfig c;
  apply_config_override(c, "odometry.features.pose_time_in_sweep=0.05");
  EXPECT_NE(config_error([&] { apply_config_override(c, "sweep_duration=0.04"); })
                .find("'odometry.features.pose_time_in_sweep' = 0.05 must lie within the sweep, "
                      "[0, 'odometry.features.sweep_duration' = 0.04]"),
            std::string::npos);
  EXPECT_DOUBLE_EQ(c.odometry.features.sweep_duration, 0.1);
  apply_config_override(c, "loop.delta_max=300");
  apply_config_override(c, "loop.delta_min=200");
  EXPECT_DOUBLE_EQ(c.loop.delta_min, 200.0);

  // A command line's overrides count together: their order does not matter.
  SaloamConfig d;
  apply_config_overrides(d, {"loop.delta_min=150", "loop.delta_max=300"});
  EXPECT_DOUBLE_EQ(d.loop.delta_min, 150.0);
  EXPECT_DOUBLE_EQ(d.loop.delta_max, 300.0);
  EXPECT_NE(config_error([&] { apply_config_overrides(d, {"loop.delta_min=400", "alpha=0.3"}); })
                .find("'loop.delta_min' = 400 must not exceed"),
            std::string::npos);
  EXPECT_DOUBLE_EQ(d.odometry.features.alpha, 0.1);  // nothing applied
  EXPECT_NE(config_error([&] { apply_config_overrides(d, {"voxel_size=0", "alpha=0.3"}); })
                .find("--set voxel_size=0: 'odometry.voxel_size' = 0 is not allowed"),
            std::string::npos);
}

TEST(ConfigRanges, YamlFileWithBadValueNamesFileKeyAndRange) {
  testing::TempDir dir;
  const auto file = dir.path() / "bad.yaml";
  std::ofstream(file) << "odometry:\n  features:\n    alpha: 0.2\n  voxel_size: -0.4\n";
  const std::string message = config_error([&] { (void)load_config(file); });
  EXPECT_NE(message.find(file.string() + ": 'odometry.voxel_size' = -0.4 is not allowed (valid: > 0)"),
            std::string::npos)
      << message;

  std::ofstream(file, std::ios::trunc) << "loop:\n  delta_min: 150\n";
  EXPECT_NE(config_error([&] { (void)load_config(file); }).find(file.string() + ": 'loop.delta_min' = 150"),
            std::string::npos);
  // Within one file the order does not matter: the pair is checked after the whole file.
  std::ofstream(file, std::ios::trunc) << "loop:\n  delta_min: 150\n  delta_max: 300\n";
  EXPECT_DOUBLE_EQ(load_config(file).loop.delta_min, 150.0);

  SaloamConfig c;
  const std::string before = config_to_yaml(c);
  EXPECT_THROW(apply_config_yaml(c, "odometry:\n  threads: 4\n  local_map_frames: 0\n", "partial.yaml"), ConfigError);
  EXPECT_EQ(config_to_yaml(c), before);  // nothing of a rejected file is applied
}

TEST(ConfigRanges, DefaultsAndShippedFilesAreValid) {
  EXPECT_NO_THROW(validate_config(SaloamConfig{}));
  EXPECT_NO_THROW(validate_config(load_config(testing::source_dir() / "config" / "real_kitti.yaml")));
  EXPECT_NO_THROW(validate_config(load_config(testing::source_dir() / "config" / "saloam.yaml")));
  SaloamConfig c;
  c.odometry.local_map_frames = 0;  // set in code: validate_config still catches it
  EXPECT_NE(config_error([&] { validate_config(c, "test"); }).find("test: 'odometry.local_map_frames' = 0"),
            std::string::npos);
}

TEST(ConfigRanges, SavedYamlShowsEachRange) {
  const std::string yaml = config_to_yaml(SaloamConfig{});
  for (const char* line : {"local_map_frames: 40  # N_m: frames in the local map [>= 1]",
                           "zeta: 0.95  # zeta: SGPR score threshold [0, 1]",
                           "detector: scancontext  # place-recognition scorer "
                           "[one of sgpr, scancontext, hybrid, ssc]",
                           "max_runner_up_ratio: .inf  # uniqueness: max inliers of a distinct fit / best [0, .inf]",
                           "use_semantics: true  # semantic assistance on/off\n",
                           "seed: 42  # seed of the N_candi random draw\n"}) {
    EXPECT_NE(yaml.find(line), std::string::npos) << line;
  }
}

}  // namespace
}  // namespace saloam
