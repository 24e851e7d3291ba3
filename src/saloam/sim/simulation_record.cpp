#include "saloam/sim/simulation_record.hpp"

#include <map>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/output_file.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

constexpr std::size_t kMaxRecordBytes = 1u << 16;

std::map<std::string, std::string> record_lines(const std::string& text) {
  std::map<std::string, std::string> values;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const auto colon = line.find(": ");
    if (line.empty() || line[0] == '#' || colon == std::string::npos) continue;
    values[line.substr(0, colon)] = line.substr(colon + 2);
  }
  return values;
}

}  // namespace

std::string simulation_record(const SimulationOptions& o) {
  const std::string route =
      o.camera_poses.empty() ? o.preset : fmt::format("given trajectory of {} poses", o.camera_poses.size());
  const std::string end = o.end_frame == std::numeric_limits<std::size_t>::max() ? "end" : std::to_string(o.end_frame);
  std::string text = "# how saloam simulate made this sequence (demo --reuse checks it)\n";
  text += fmt::format("route: {}\nframes: {}:{}\nstride: {}\nseed: {}\nbeams: {}\nazimuth_steps: {}\n", route,
                      o.first_frame, end, o.stride, o.seed, o.beams, o.azimuth_steps);
  text += fmt::format("labels: {}\nskew: {}\ndynamic_objects: {}\n", o.labels == LabelMode::kNoisy ? "noisy" : "gt",
                      o.skew, o.world.dynamic_objects);
  // A tilted sensor or turned scans only (records of level ones stay as they were).
  if (!o.mount_rpy_deg.isZero()) text += fmt::format("mount_rpy_deg: {:.6g}\n", fmt::join(o.mount_rpy_deg, " "));
  if (!o.cloud_frame_rpy_deg.isZero()) {
    text += fmt::format("cloud_frame_rpy_deg: {:.6g}\n", fmt::join(o.cloud_frame_rpy_deg, " "));
  }
  if (!o.imu.empty()) text += fmt::format("imu: {}\n", o.imu);
  if (!o.passes.empty()) {
    // Passes of one world: the pass drawn and where its first frame lies in
    // the world (T_world<-L0, 3x4 row-major), so that two passes' poses
    // relate: T_a0<-b0 = origin_a^-1 origin_b.
    std::vector<std::string> passes;
    for (const auto& p : o.passes) passes.push_back(route_pass_text(p));
    const std::vector<Pose> trajectory = source_lidar_trajectory(o);
    const Pose& origin = trajectory.at(selected_frames(o, trajectory.size()).front());
    double v[12];
    pose_to_3x4(origin, v);
    text += fmt::format("passes: {}\npass: {}\norigin: {:.9f}\n", fmt::join(passes, ","), o.pass, fmt::join(v, v + 12, " "));
  }
  return text;
}

void write_simulation_record(const fs::path& folder, const SimulationOptions& options) {
  write_file_atomically(folder / "simulation.yaml", simulation_record(options));
}

std::vector<std::string> simulation_differences(const fs::path& folder, const SimulationOptions& options) {
  const fs::path file = folder / "simulation.yaml";
  if (!path_taken(file)) throw InputError(file, "not found: the sequence does not say how it was simulated");
  const auto kept = record_lines(read_file(file, kMaxRecordBytes, "simulation record"));
  const auto asked = record_lines(simulation_record(options));
  std::vector<std::string> differences;
  for (const auto& [key, value] : asked) {
    const auto it = kept.find(key);
    const std::string was = it == kept.end() ? "(not recorded)" : it->second;
    if (was != value) differences.push_back(fmt::format("{}: {}, asked for {}", key, was, value));
  }
  return differences;
}

OutputFolder open_sequence_output(const fs::path& out_dir) {
  const bool holds_something =
      std::any_of(kSequenceFiles.begin(), kSequenceFiles.end(), [&](const auto& name) { return path_taken(out_dir / name); }) ||
      path_taken(out_dir / "velodyne") || path_taken(out_dir / "labels") || path_taken(out_dir / "summary.json");
  if (holds_something && recorded_command(out_dir) != "simulate") {
    throw InputError(out_dir, "holds a sequence or results that saloam simulate did not write; they are left as they "
                              "are: choose another --out");
  }
  return OutputFolder(out_dir, "simulate", kSequenceFiles);
}

}  // namespace saloam
