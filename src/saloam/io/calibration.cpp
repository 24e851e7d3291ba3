#include "saloam/io/calibration.hpp"

#include <array>
#include <cmath>
#include <optional>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/io/text_input.hpp"

namespace saloam {
namespace {

std::optional<std::vector<double>> parse_values(const std::string& text) {
  std::istringstream ss(text);
  std::vector<double> v;
  std::string token;
  while (ss >> token) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(token, &used));
      if (used != token.size() || !std::isfinite(v.back())) return std::nullopt;
    } catch (const std::exception&) {
      return std::nullopt;
    }
  }
  return v;
}

/// The first word of `text` that reads as a non-finite number ("nan", "inf", "1e999"), if any.
std::optional<std::string> non_finite_word(const std::string& text) {
  std::istringstream ss(text);
  std::string token;
  while (ss >> token) {
    try {
      std::size_t used = 0;
      const double v = std::stod(token, &used);
      if (used == token.size() && !std::isfinite(v)) return token;
    } catch (const std::out_of_range&) {
      return token;  // beyond double's range
    } catch (const std::exception&) {
    }
  }
  return std::nullopt;
}

std::string trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

}  // namespace

Pose read_velo_to_cam(const std::filesystem::path& file, int sequence) {
  auto in = open_text_file(file, "calibration file");
  return read_velo_to_cam(in, file, sequence);
}

Pose read_velo_to_cam(std::istream& in, const std::filesystem::path& file, int sequence) {
  std::optional<Pose> keyed;  // the wanted "KEY:" line
  std::optional<Pose> bare;   // the first line with 12 numbers and no key
  std::size_t bare_lines = 0;  // more than one: a pose file, not a calibration
  const std::string wanted = sequence >= 0 ? fmt::format("{:02d}", sequence) : std::string("Tr");
  for_each_text_line(in, file, [&](const std::string& line, std::size_t line_no) {
    if (keyed) return;
    const auto colon = line.find(':');
    const std::string key = colon == std::string::npos ? "" : trimmed(line.substr(0, colon));
    const auto values = parse_values(colon == std::string::npos ? line : line.substr(colon + 1));
    const bool relevant = key == wanted || (key.empty() && values && values->size() == 12);
    if (relevant && key.empty()) ++bare_lines;
    if (!relevant || (key.empty() && bare)) return;
    if (!values || values->size() != 12) {
      const std::string name = key.empty() ? "Tr" : key;
      if (const auto bad = non_finite_word(colon == std::string::npos ? line : line.substr(colon + 1))) {
        throw InputError(file, fmt::format("line {}: '{}' holds the non-finite value '{}' (12 finite numbers, 3x4 "
                                           "row-major)",
                                           line_no, name, bad->substr(0, 40)));
      }
      throw InputError(file, fmt::format("line {}: '{}' needs 12 numbers (3x4 row-major)", line_no, name));
    }
    const Pose T = checked_rigid_pose(pose_from_3x4(values->data()), file, line_no,
                                      fmt::format("rotation of '{}'", key.empty() ? "Tr" : key));
    (key.empty() ? bare : keyed) = T;
  });
  if (keyed) return *keyed;
  if (bare_lines > 1) {
    throw InputError(file, fmt::format("no '{}:' line, and {} lines of 12 numbers: a pose file, not a calibration",
                                       wanted, bare_lines));
  }
  if (bare) return *bare;
  throw InputError(file, sequence >= 0 ? fmt::format("no line for sequence {}", wanted)
                                       : std::string("no 'Tr:' line (velodyne to camera 0 transform)"));
}

void write_calib(const std::filesystem::path& file, const Pose& velo_to_cam) {
  AtomicFile file_out(file);
  std::ostream& out = file_out.stream();
  // KITTI odometry's rectified camera projections (sequences 00-02), so that
  // tools expecting all five lines can read the file.
  out << "P0: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 0.000000000000e+00 0.000000000000e+00 "
         "7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 0.000000000000e+00 0.000000000000e+00 "
         "1.000000000000e+00 0.000000000000e+00\n";
  out << "P1: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 -3.861448000000e+02 0.000000000000e+00 "
         "7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 0.000000000000e+00 0.000000000000e+00 "
         "1.000000000000e+00 0.000000000000e+00\n";
  out << "P2: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 4.538225000000e+01 0.000000000000e+00 "
         "7.188560000000e+02 1.852157000000e+02 -1.130887000000e-01 0.000000000000e+00 0.000000000000e+00 "
         "1.000000000000e+00 3.779761000000e-03\n";
  out << "P3: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 -3.372877000000e+02 0.000000000000e+00 "
         "7.188560000000e+02 1.852157000000e+02 2.369057000000e+00 0.000000000000e+00 0.000000000000e+00 "
         "1.000000000000e+00 4.915215000000e-03\n";
  std::array<double, 12> v{};
  pose_to_3x4(velo_to_cam, v.data());
  out << "Tr: " << fmt::format("{:.12e}", fmt::join(v, " ")) << '\n';
  file_out.commit();
}

std::vector<Pose> camera_to_lidar_poses(const std::vector<Pose>& camera_poses, const Pose& velo_to_cam) {
  const Pose tr_inv = velo_to_cam.inverse();
  std::vector<Pose> out;
  out.reserve(camera_poses.size());
  for (const auto& P : camera_poses) out.push_back(orthonormalized(tr_inv * P * velo_to_cam));
  return out;
}

std::vector<Pose> lidar_to_camera_poses(const std::vector<Pose>& lidar_poses, const Pose& velo_to_cam) {
  const Pose tr_inv = velo_to_cam.inverse();
  std::vector<Pose> out;
  out.reserve(lidar_poses.size());
  for (const auto& Q : lidar_poses) out.push_back(orthonormalized(velo_to_cam * Q * tr_inv));
  return out;
}

}  // namespace saloam
