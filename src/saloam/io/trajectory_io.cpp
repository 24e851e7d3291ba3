#include "saloam/io/trajectory_io.hpp"

#include <array>
#include <cmath>
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

/// Appends a TUM line's timestamp, which must be later than the previous one.
void push_tum_timestamp(Trajectory& traj, double t, std::size_t& previous_line, const std::filesystem::path& file,
                        std::size_t line_no) {
  if (!traj.timestamps.empty()) check_time_increases(traj.timestamps.back(), previous_line, t, file, line_no);
  traj.timestamps.push_back(t);
  previous_line = line_no;
}

Pose tum_pose(const std::vector<double>& v, const std::filesystem::path& file, std::size_t line_no) {
  Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
  if (std::abs(q.norm() - 1.0) > 1e-2) {
    throw InputError(file, fmt::format("line {}: quaternion norm {:.4f} is not 1", line_no, q.norm()));
  }
  Pose T = Pose::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
  return T;
}

}  // namespace

std::vector<Pose> read_kitti_poses(const std::filesystem::path& file) {
  auto in = open_text_file(file);
  return read_kitti_poses(in, file);
}

std::vector<Pose> read_kitti_poses(std::istream& in, const std::filesystem::path& file) {
  std::vector<Pose> poses;
  for_each_number_line(in, file, [&](const std::vector<double>& v, std::size_t line_no) {
    if (v.size() != 12) {
      throw InputError(file, fmt::format("line {}: expected 12 numbers (KITTI 3x4 pose), found {}", line_no, v.size()));
    }
    poses.push_back(checked_rigid_pose(pose_from_3x4(v.data()), file, line_no));
  });
  if (poses.empty()) throw InputError(file, "no poses in file");
  return poses;
}

std::string kitti_pose_line(const Pose& pose) {
  std::array<double, 12> v{};
  pose_to_3x4(pose, v.data());
  return fmt::format("{:.9e}", fmt::join(v, " "));
}

void write_kitti_poses(const std::filesystem::path& file, const std::vector<Pose>& poses) {
  AtomicFile out(file);
  for (const auto& T : poses) out.stream() << kitti_pose_line(T) << '\n';
  out.commit();
}

Trajectory read_tum_trajectory(const std::filesystem::path& file) {
  auto in = open_text_file(file);
  return read_tum_trajectory(in, file);
}

Trajectory read_tum_trajectory(std::istream& in, const std::filesystem::path& file) {
  Trajectory traj;
  std::size_t previous_line = 0;
  for_each_number_line(in, file, [&](const std::vector<double>& v, std::size_t line_no) {
    if (v.size() != 8) {
      throw InputError(file, fmt::format("line {}: expected 8 numbers (TUM: t x y z qx qy qz qw), found {}", line_no,
                                         v.size()));
    }
    push_tum_timestamp(traj, v[0], previous_line, file, line_no);
    traj.poses.push_back(tum_pose(v, file, line_no));
  });
  if (traj.empty()) throw InputError(file, "no poses in file");
  return traj;
}

std::string tum_pose_line(double timestamp, const Pose& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d t = pose.translation();
  // Nanoseconds (LiDAR drivers stamp in ns): times 1e-9 s apart stay apart.
  return fmt::format("{:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}", timestamp, t.x(), t.y(), t.z(),
                     q.x(), q.y(), q.z(), q.w());
}

void write_tum_trajectory(const std::filesystem::path& file, const Trajectory& trajectory) {
  if (trajectory.timestamps.size() != trajectory.poses.size()) {
    throw InputError(file, "trajectory has different numbers of timestamps and poses");
  }
  AtomicFile out(file);
  out.stream() << "# timestamp x y z qx qy qz qw\n";
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    out.stream() << tum_pose_line(trajectory.timestamps[i], trajectory.poses[i]) << '\n';
  }
  out.commit();
}

Trajectory read_trajectory(const std::filesystem::path& file, TrajectoryFormat* format) {
  auto in = open_text_file(file);
  return read_trajectory(in, file, format);
}

Trajectory read_trajectory(std::istream& in, const std::filesystem::path& file, TrajectoryFormat* format) {
  Trajectory traj;
  std::size_t columns = 0;
  std::size_t previous_line = 0;
  for_each_number_line(in, file, [&](const std::vector<double>& v, std::size_t line_no) {
    if (columns == 0) {
      columns = v.size();
      if (columns != 12 && columns != 8) {
        throw InputError(file, fmt::format("line {}: {} numbers: neither KITTI (12) nor TUM (8)", line_no, columns));
      }
    }
    if (v.size() != columns) {
      throw InputError(file, fmt::format("line {}: expected {} numbers like the first line, found {}", line_no,
                                         columns, v.size()));
    }
    if (columns == 12) {
      traj.timestamps.push_back(0.1 * static_cast<double>(traj.poses.size()));
      traj.poses.push_back(checked_rigid_pose(pose_from_3x4(v.data()), file, line_no));
    } else {
      push_tum_timestamp(traj, v[0], previous_line, file, line_no);
      traj.poses.push_back(tum_pose(v, file, line_no));
    }
  });
  if (traj.empty()) throw InputError(file, "no poses in file");
  if (format) *format = columns == 12 ? TrajectoryFormat::kKitti : TrajectoryFormat::kTum;
  return traj;
}

std::vector<double> read_times(const std::filesystem::path& file) {
  auto in = open_text_file(file);
  return read_times(in, file);
}

std::vector<double> read_times(std::istream& in, const std::filesystem::path& file) {
  std::vector<double> times;
  std::size_t previous_line = 0;
  for_each_number_line(in, file, [&](const std::vector<double>& v, std::size_t line_no) {
    if (v.size() != 1) throw InputError(file, fmt::format("line {}: expected one timestamp, found {} numbers", line_no, v.size()));
    if (!times.empty()) check_time_increases(times.back(), previous_line, v[0], file, line_no);
    times.push_back(v[0]);
    previous_line = line_no;
  });
  return times;
}

void write_times(const std::filesystem::path& file, const std::vector<double>& times) {
  AtomicFile out(file);
  for (double t : times) out.stream() << fmt::format("{:.6e}", t) << '\n';
  out.commit();
}

}  // namespace saloam
