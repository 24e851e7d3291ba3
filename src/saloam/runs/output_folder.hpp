#pragma once
// The output folder of a run over a sequence: created on demand, and never
// the sequence folder itself, whose poses.txt (the ground truth) a run's
// poses.txt would overwrite.

#include <filesystem>

#include <optional>

namespace saloam {

/// Creates `out_dir` (and its parents); InputError when it is the run's
/// sequence folder `sequence` (when the frames come from one), naming both
/// and what would be lost.
void prepare_output_folder(const std::filesystem::path& out_dir, const std::optional<std::filesystem::path>& sequence);

}  // namespace saloam
