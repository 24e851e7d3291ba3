#pragma once
// Data recipes of the trainers (`saloam sgpr-train`, `saloam segment-train`):
// which sequences to learn from and which to validate on, each a simulated
// sequence rendered in memory along a trajectory (never written to disk) or
// a sequence folder in the SemanticKITTI layout. No libtorch here.
//
//   defaults: {calib: FILE, frame_step: 5, seed: 1, labels: noisy, beams: 64}   (optional)
//   train:      [{simulate: POSES.txt, frames: "0:4541"} | {simulate: "preset:urban-loop"} |
//                {folder: DIR, labels: DIR, weight: W}, ...]
//   validation: [...]
// Relative paths are relative to the recipe file.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "saloam/sim/simulator.hpp"

namespace saloam {

/// One source of a data recipe: a simulated sequence or a sequence folder,
/// every k-th frame.
struct SourceSpec {
  enum class Kind { kSimulated, kFolder };
  Kind kind = Kind::kSimulated;
  std::filesystem::path path;   ///< simulated: KITTI pose file (camera frame); folder: the sequence folder
  std::string preset;           ///< simulated: a built-in route instead of a pose file ("simulate: preset:NAME")
  std::filesystem::path calib;  ///< simulated: calib.txt with Tr, or a per-sequence list picked by the pose file's name
  std::string frames;           ///< source frames "A:B" (empty = all)
  std::size_t frame_step = 5;   ///< every k-th frame
  std::uint64_t seed = 1;       ///< simulated: world and label-noise seed
  bool noisy_labels = true;     ///< simulated: emulated network labels (else ground truth)
  int beams = 64;               ///< simulated: 64, 32 or 16 beams
  std::filesystem::path labels; ///< folder: .label folder instead of labels/ (e.g. predictions)
  /// Training draws each scan of this source `weight` times as often as a
  /// scan of a weight-1 source: a few real scans beside thousands of
  /// simulated ones get a share of the batches of their own. Not part of the
  /// data's identity (name(), to_json(), the scan cache).
  double weight = 1.0;

  /// A short name for messages and cache files: "sim-00-s1-k5-noisy", "sim-05-s3-k10-gt-b16", "folder-<dir>-k5".
  [[nodiscard]] std::string name() const;
  [[nodiscard]] nlohmann::json to_json() const;
};

struct DataRecipe {
  std::vector<SourceSpec> train, validation;
};

/// Reads a recipe; entries start from `defaults` (then the recipe's own
/// `defaults:`). Throws InputError naming the file for a missing file, bad
/// YAML or a bad entry.
DataRecipe read_data_recipe(const std::filesystem::path& file, const SourceSpec& defaults = {});
nlohmann::json recipe_to_json(const DataRecipe& recipe);

/// The one path rule (core/path_rules.hpp) for a training run writing into
/// the folder `out`: it never equals, holds or lies inside the recipe file
/// `recipe_file` (empty when a resumed run reads its own copy), the model
/// `init` it starts from (empty: none) or any file or folder a source of
/// `recipe` reads. InputError naming both paths, before anything is written.
void check_training_paths(const DataRecipe& recipe, const std::filesystem::path& recipe_file,
                          const std::filesystem::path& init, const std::filesystem::path& out);

/// The simulator's options for a simulated source (labels as the source
/// says). InputError for an unreadable pose or calibration file.
SimulationOptions simulation_options(const SourceSpec& spec);

}  // namespace saloam
