#include "saloam/train/data_recipe.hpp"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/core/path_rules.hpp"
#include "saloam/core/yaml_documents.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/sim/trajectories.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

/// A recipe lists a few dozen sequences; a larger file is not one.
constexpr std::size_t kMaxRecipeBytes = std::size_t{1} << 20;

/// Tr from a calib.txt (`Tr:` line) or, failing that, from a per-sequence
/// list (`NN: ...`) picked by the pose file's name (00.txt), as `saloam simulate` does.
Pose velo_to_cam_for(const fs::path& calib, const fs::path& trajectory) {
  try {
    return read_velo_to_cam(calib);
  } catch (const InputError&) {
    const std::string stem = trajectory.stem().string();
    const bool numeric =
        !stem.empty() && std::all_of(stem.begin(), stem.end(), [](unsigned char c) { return std::isdigit(c); });
    if (!numeric || !fs::is_regular_file(calib)) throw;
    // A sequence number of a few digits ("00".."21"); a longer name is no sequence.
    if (stem.size() > 6) throw;
    return read_velo_to_cam(calib, std::stoi(stem));
  }
}

int read_beams(const YAML::Node& node, const fs::path& file, const std::string& where) {
  const int beams = node.as<int>();
  if (beams != 64 && beams != 32 && beams != 16)
    throw InputError(file, fmt::format("{}: beams must be 64, 32 or 16, not {}", where, beams));
  return beams;
}

double read_weight(const YAML::Node& node, const fs::path& file, const std::string& where) {
  const double weight = node.as<double>();
  if (!(weight > 0.0 && weight <= 1000.0))
    throw InputError(file, fmt::format("{}: weight must lie in (0, 1000], not {}", where, node.Scalar()));
  return weight;
}

/// InputError when a key of the map `node` at `where` (empty: the top) is not
/// a name or is given twice (key_problem; yaml-cpp's own conversion error
/// would not name the file).
void check_keys(const YAML::Node& node, const fs::path& file, const std::string& where) {
  if (const auto problem = key_problem(node, where); !problem.empty()) throw InputError(file, problem);
}

fs::path resolve(const fs::path& base, const std::string& text) {
  const fs::path p(text);
  return p.is_absolute() ? p : base / p;
}

SourceSpec read_source(const YAML::Node& node, const SourceSpec& defaults, const fs::path& base,
                            const fs::path& file, const std::string& where) {
  if (!node.IsMap()) throw InputError(file, where + ": expected a map with `simulate:` or `folder:`");
  SourceSpec spec = defaults;
  try {
    if (node["simulate"] && node["folder"]) throw InputError(file, where + ": give `simulate:` or `folder:`, not both");
    if (node["simulate"]) {
      spec.kind = SourceSpec::Kind::kSimulated;
      const auto text = node["simulate"].as<std::string>();
      if (text.rfind("preset:", 0) == 0) {
        spec.preset = text.substr(7);
        const auto names = preset_names();
        if (std::find(names.begin(), names.end(), spec.preset) == names.end())
          throw InputError(file, where + ": unknown preset '" + spec.preset + "' (" + fmt::format("{}", fmt::join(names, ", ")) + ")");
      } else {
        spec.path = resolve(base, text);
      }
    } else if (node["folder"]) {
      spec.kind = SourceSpec::Kind::kFolder;
      spec.path = resolve(base, node["folder"].as<std::string>());
    } else {
      throw InputError(file, where + ": needs `simulate: POSES.txt` or `folder: DIR`");
    }
    check_keys(node, file, where);
    for (const auto& kv : node) {
      const std::string key = kv.first.Scalar();  // a name: check_keys
      if (key == "simulate" || key == "folder") continue;
      if (key == "calib") spec.calib = resolve(base, kv.second.as<std::string>());
      else if (key == "frames") spec.frames = kv.second.as<std::string>();
      else if (key == "frame_step") spec.frame_step = kv.second.as<std::size_t>();
      else if (key == "seed") spec.seed = kv.second.as<std::uint64_t>();
      else if (key == "weight") spec.weight = read_weight(kv.second, file, where);
      else if (key == "beams" && spec.kind == SourceSpec::Kind::kSimulated) spec.beams = read_beams(kv.second, file, where);
      else if (key == "labels" && spec.kind == SourceSpec::Kind::kSimulated) {
        const auto v = kv.second.as<std::string>();
        if (v != "noisy" && v != "gt") throw InputError(file, where + ": labels must be noisy or gt, not '" + v + "'");
        spec.noisy_labels = v == "noisy";
      } else if (key == "labels") spec.labels = resolve(base, kv.second.as<std::string>());
      else throw InputError(file, where + ": unknown key '" + key + "'");
    }
  } catch (const YAML::Exception& e) {
    throw InputError(file, where + ": " + e.what());
  }
  if (spec.frame_step == 0) throw InputError(file, where + ": frame_step must be at least 1");
  if (spec.kind == SourceSpec::Kind::kSimulated && !spec.preset.empty()) {
    return spec;  // a built-in route needs no files
  }
  if (spec.kind == SourceSpec::Kind::kSimulated) {
    if (!fs::is_regular_file(spec.path))
      throw InputError(spec.path, "pose file not found (" + where + " of " + file.string() + ")");
    if (spec.calib.empty()) throw InputError(file, where + ": a simulated source needs `calib:` (here or in defaults)");
    if (!fs::is_regular_file(spec.calib))
      throw InputError(spec.calib, "calibration file not found (" + where + " of " + file.string() + ")");
  } else if (!fs::is_directory(spec.path)) {
    throw InputError(spec.path, "sequence folder not found (" + where + " of " + file.string() + ")");
  }
  return spec;
}

}  // namespace

std::string SourceSpec::name() const {
  if (kind == Kind::kSimulated)
    return fmt::format("sim-{}{}-s{}-k{}-{}{}", preset.empty() ? path.stem().string() : preset,
                       frames.empty() ? "" : "-f" + frames, seed, frame_step, noisy_labels ? "noisy" : "gt",
                       beams == 64 ? "" : fmt::format("-b{}", beams));
  std::string n = fmt::format("folder-{}{}-k{}", path.filename().string(), frames.empty() ? "" : "-f" + frames, frame_step);
  return n;
}

nlohmann::json SourceSpec::to_json() const {
  nlohmann::json j;
  j[kind == Kind::kSimulated ? "simulate" : "folder"] =
      preset.empty() ? fs::absolute(path).lexically_normal().string() : "preset:" + preset;
  if (kind == Kind::kSimulated) {
    if (!calib.empty()) j["calib"] = fs::absolute(calib).lexically_normal().string();
    j["seed"] = seed;
    j["labels"] = noisy_labels ? "noisy" : "gt";
    if (beams != 64) j["beams"] = beams;  // 64 left out: older graph caches stay valid
  } else if (!labels.empty()) {
    j["labels"] = fs::absolute(labels).lexically_normal().string();
  }
  j["frames"] = frames;
  j["frame_step"] = frame_step;
  return j;
}

DataRecipe read_data_recipe(const fs::path& file, const SourceSpec& given_defaults) {
  const YamlDocument document = load_yaml_document(read_file(file, kMaxRecipeBytes, "data recipe"), "a data recipe");
  if (!document.problem.empty()) throw InputError(file, document.problem);
  const YAML::Node& root = document.root;
  if (!root.IsMap()) throw InputError(file, "expected a map with `train:` and `validation:` lists");
  check_keys(root, file, "");
  const fs::path base = file.parent_path();
  SourceSpec defaults = given_defaults;
  if (const auto d = root["defaults"]) {
    if (!d.IsMap()) throw InputError(file, "defaults: expected a map");
    check_keys(d, file, "defaults");
    try {
      for (const auto& kv : d) {
        const std::string key = kv.first.Scalar();  // a name: check_keys
        if (key == "calib") defaults.calib = resolve(base, kv.second.as<std::string>());
        else if (key == "frame_step") defaults.frame_step = kv.second.as<std::size_t>();
        else if (key == "seed") defaults.seed = kv.second.as<std::uint64_t>();
        else if (key == "labels") defaults.noisy_labels = kv.second.as<std::string>() != "gt";
        else if (key == "beams") defaults.beams = read_beams(kv.second, file, "defaults");
        else throw InputError(file, "defaults: unknown key '" + key + "'");
      }
    } catch (const YAML::Exception& e) {
      throw InputError(file, std::string("defaults: ") + e.what());
    }
  }
  DataRecipe recipe;
  for (const char* section : {"train", "validation"}) {
    const auto list = root[section];
    if (!list || !list.IsSequence() || list.size() == 0)
      throw InputError(file, std::string("needs a non-empty `") + section + ":` list");
    auto& out = std::string(section) == "train" ? recipe.train : recipe.validation;
    for (std::size_t i = 0; i < list.size(); ++i)
      out.push_back(read_source(list[i], defaults, base, file, fmt::format("{}[{}]", section, i)));
  }
  for (const auto& kv : root)
    if (const std::string k = kv.first.Scalar(); k != "train" && k != "validation" && k != "defaults")
      throw InputError(file, "unknown key '" + k + "'");
  return recipe;
}

nlohmann::json recipe_to_json(const DataRecipe& recipe) {
  nlohmann::json j;
  j["train"] = nlohmann::json::array();
  j["validation"] = nlohmann::json::array();
  for (const char* section : {"train", "validation"})
    for (const auto& s : std::string(section) == "train" ? recipe.train : recipe.validation) {
      nlohmann::json entry = s.to_json();
      if (s.weight != 1.0) entry["weight"] = s.weight;
      j[section].push_back(std::move(entry));
    }
  return j;
}

SimulationOptions simulation_options(const SourceSpec& spec) {
  SimulationOptions options;
  if (!spec.preset.empty()) {
    options.preset = spec.preset;
  } else {
    options.camera_poses = read_kitti_poses(spec.path);
    if (options.camera_poses.size() < 2) throw InputError(spec.path, "needs at least two poses");
    if (spec.calib.empty()) throw InputError(spec.path, "a simulated source needs a calib file (calib: FILE)");
    options.velo_to_cam = velo_to_cam_for(spec.calib, spec.path);
    options.velo_to_cam_given = true;
  }
  const FrameRange range = FrameRange::parse(spec.frames, "frames");
  options.first_frame = range.first;
  options.end_frame = range.end;
  options.stride = spec.frame_step;
  options.seed = spec.seed;
  options.beams = spec.beams;
  options.labels = spec.noisy_labels ? LabelMode::kNoisy : LabelMode::kGroundTruth;
  options.show_progress = false;
  return options;
}

void check_training_paths(const DataRecipe& recipe, const std::filesystem::path& recipe_file,
                          const std::filesystem::path& init, const std::filesystem::path& out) {
  PathRules rules;
  rules.input("--data", recipe_file).input("--init", init);
  for (const auto* sources : {&recipe.train, &recipe.validation}) {
    for (const SourceSpec& s : *sources) {
      const bool folder = s.kind == SourceSpec::Kind::kFolder;
      rules.input(folder ? "the recipe's folder" : "the recipe's simulate", s.path)
          .input("the recipe's labels", s.labels)
          .input("the recipe's calib", s.calib);
    }
  }
  rules.output("--out", out, OutputUse::kFolder).check();
}

}  // namespace saloam
