#pragma once
// A small fake output folder of `saloam slam` (map.ply, poses, loops.csv,
// summary.json) with the sequence it points at, for the viewer's tests.

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/ply.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace saloam::testing {

struct FakeRun {
  std::filesystem::path run_dir, sequence;
  std::size_t map_points = 0, frames = 0, loops_accepted = 0, loops_verified = 0;
};

/// A street: road, buildings on both sides, trees; `map_points` points in all.
inline LabelledCloud fake_street(std::size_t map_points) {
  LabelledCloud map;
  map.has_labels = true;
  const std::uint16_t classes[] = {cls::kRoad, cls::kBuilding, cls::kVegetation, cls::kCar};
  for (std::size_t i = 0; i < map_points; ++i) {
    const std::uint16_t label = classes[i % 4];
    const float t = static_cast<float>(i) / static_cast<float>(map_points);
    const float x = 100.0F * t;
    const float u = std::fmod(static_cast<float>(i) * 0.618034F, 1.0F);
    Eigen::Vector3f p(x, 0, 0);
    if (label == cls::kRoad) p = {x, 14.0F * u - 7.0F, 0.0F};
    if (label == cls::kBuilding) p = {x, (i % 8 < 4 ? -12.0F : 12.0F), 10.0F * u};
    if (label == cls::kVegetation) p = {x, (i % 8 < 4 ? -9.0F : 9.0F), 3.0F + 2.0F * u};
    if (label == cls::kCar) p = {x, 4.0F, 1.5F * u};
    map.push_back(p, 0.5F, label);
  }
  return map;
}

/// One scan: a ring of road and building points around the sensor.
inline LabelledCloud fake_scan(std::size_t points) {
  LabelledCloud scan;
  scan.has_labels = true;
  for (std::size_t i = 0; i < points; ++i) {
    const double angle = 2.0 * M_PI * static_cast<double>(i) / static_cast<double>(points);
    const bool road = i % 2 == 0;
    const float r = road ? 8.0F : 15.0F;
    scan.push_back(Eigen::Vector3f(r * static_cast<float>(std::cos(angle)), r * static_cast<float>(std::sin(angle)),
                                   road ? -1.7F : 2.0F),
                   0.5F, road ? cls::kRoad : cls::kBuilding);
  }
  return scan;
}

inline std::vector<Pose> straight_poses(std::size_t frames, double step, double drift) {
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < frames; ++i) {
    Pose p = Pose::Identity();
    p.translation() = Eigen::Vector3d(step * static_cast<double>(i), drift * static_cast<double>(i * i), 0);
    poses.push_back(p);
  }
  return poses;
}

inline void write_tum(const std::filesystem::path& file, const std::vector<Pose>& poses) {
  Trajectory trajectory;
  trajectory.poses = poses;
  for (std::size_t i = 0; i < poses.size(); ++i) trajectory.timestamps.push_back(0.1 * static_cast<double>(i));
  write_tum_trajectory(file, trajectory);
}

/// loops.csv with the columns the viewer reads (and a quoted field with commas, as `saloam slam` writes).
inline void write_loops(const std::filesystem::path& file, std::size_t frames, std::size_t& accepted,
                        std::size_t& verified) {
  std::ofstream out(file);
  out << "query_frame,match_frame,score,accepted,reason,relative_pose_3x4\n";
  accepted = verified = 0;
  for (std::size_t q = 10; q < frames; q += 7) {
    const bool ok = q % 2 == 1;
    out << q << ',' << q - 9 << ",0.9," << (ok ? 1 : 0) << ",\"few inliers, 12 < 30\",1 0 0 0 0 1 0 0 0 0 1 0\n";
    accepted += ok;
    ++verified;
  }
}

/// Writes the run folder `root`/run and its sequence `root`/seq (`frames` scans).
inline FakeRun write_fake_run(const std::filesystem::path& root, std::size_t map_points, std::size_t frames = 40,
                              std::size_t scan_points = 3000) {
  FakeRun run;
  run.run_dir = root / "run";
  run.sequence = root / "seq";
  run.map_points = map_points;
  run.frames = frames;
  std::filesystem::create_directories(run.run_dir);

  SequenceWriter writer(run.sequence);
  for (std::size_t i = 0; i < frames; ++i) writer.write_scan(i, fake_scan(scan_points));
  writer.write_camera_poses(straight_poses(frames, 2.5, 0.0));
  writer.write_calib(Pose::Identity());

  write_ply(run.run_dir / "map.ply", fake_street(map_points));
  write_tum(run.run_dir / "poses_tum.txt", straight_poses(frames, 2.5, 0.001));
  write_tum(run.run_dir / "poses_odometry_tum.txt", straight_poses(frames, 2.5, 0.004));
  write_loops(run.run_dir / "loops.csv", frames, run.loops_accepted, run.loops_verified);
  std::ofstream(run.run_dir / "summary.json")
      << nlohmann::json{{"sequence", std::filesystem::absolute(run.sequence).string()}, {"first_frame", 0}}.dump(2);
  return run;
}

/// The JSON data inside a viewer page.
inline nlohmann::json page_data(const std::string& page) {
  const std::string start = "const SALOAM_DATA = ";
  const std::size_t begin = page.find(start);
  if (begin == std::string::npos) return {};
  const std::size_t end = page.find(";</script>", begin);
  return nlohmann::json::parse(page.substr(begin + start.size(), end - begin - start.size()));
}

/// Float32 values sent as base64 (the page's poses), decoded as the page decodes them.
inline std::vector<float> base64_floats(const std::string& text) {
  static const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string bytes;
  std::uint32_t buffer = 0;
  int bits = 0;
  for (const char c : text) {
    if (c == '=') break;
    buffer = (buffer << 6) | static_cast<std::uint32_t>(alphabet.find(c));
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      bytes.push_back(static_cast<char>((buffer >> bits) & 0xFFU));
    }
  }
  std::vector<float> values(bytes.size() / 4);
  if (!values.empty()) std::memcpy(values.data(), bytes.data(), values.size() * 4);  // data() may be null when empty
  return values;
}

inline std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace saloam::testing
