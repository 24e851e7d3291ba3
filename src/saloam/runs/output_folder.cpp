#include "saloam/runs/output_folder.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"

namespace saloam {

void prepare_output_folder(const std::filesystem::path& out_dir, const std::optional<std::filesystem::path>& sequence) {
  std::error_code error;
  const auto out = std::filesystem::weakly_canonical(out_dir, error);
  const auto root = sequence ? std::filesystem::weakly_canonical(*sequence, error) : std::filesystem::path();
  if (sequence && !error && out == root) {
    throw InputError(out_dir, fmt::format("is the sequence folder {}: the run's poses.txt would overwrite its ground "
                                          "truth; choose another output folder",
                                          sequence->string()));
  }
  create_folder(out_dir);
}

std::optional<Pose> output_velo_to_cam(const SourceInfo& source) {
  if (!source.velo_to_cam) {
    spdlog::info("{}: no calibration: pose files hold LiDAR-frame poses, not the KITTI camera convention", source.name);
  }
  return source.velo_to_cam;
}

}  // namespace saloam
