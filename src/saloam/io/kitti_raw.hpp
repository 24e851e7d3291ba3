#pragma once
// The text files of a KITTI raw drive (Geiger et al., "Vision meets
// Robotics: The KITTI Dataset", IJRR 2013; raw data development kit):
//   velodyne_points/timestamps{,_start,_end}.txt, oxts/timestamps.txt
//       one "YYYY-MM-DD hh:mm:ss.fffffffff" per line (the recording PC's
//       clock); timestamps.txt is when the laser faced forward (the camera
//       trigger), _start/_end when the sweep began and ended
//   oxts/data/NNNNNNNNNN.txt
//       one line of 30 numbers from the GPS/INS: lat lon [deg] alt [m]
//       roll pitch yaw [rad] (yaw 0 = east, counter-clockwise), then
//       velocities, accelerations, rates, accuracies and status (not used)
//   calib_imu_to_velo.txt
//       "R: 9 numbers" (row-major) and "T: 3 numbers" [m]: p_velo = R p_imu + T
//       (a "calib_time:" line is ignored)
// The scans (velodyne_points/data/*.bin) are KITTI .bin files (scan_io.hpp).
// No library: KITTI's raw-data devkit is MATLAB and sample C++ code, and
// Debian packages none; convertOxtsToPose is a few lines, written out here
// and checked against the published reference of drive 0005
// (tests/io/kitti_raw_test.cpp).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <istream>
#include <string_view>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

struct OxtsRecord {
  double lat = 0.0, lon = 0.0, alt = 0.0;       ///< [deg], [deg], [m]
  double roll = 0.0, pitch = 0.0, yaw = 0.0;  ///< [rad]
};

/// One oxts/data file: a line of 30 numbers (the first six are used).
/// InputError naming the file for fewer than 6 or more than 30 numbers, a
/// word that is not a number, a non-finite value, a latitude beyond +-85 deg
/// (the Mercator projection's domain), a longitude beyond +-180 deg, an
/// altitude beyond +-100 km or an angle beyond +-7 rad.
OxtsRecord parse_oxts(std::istream& in, const std::filesystem::path& file);
OxtsRecord read_oxts(const std::filesystem::path& file);
/// Writes a line of 30 numbers (the rest 0, status words 4 / 10 as a fixed RTK solution).
void write_oxts(const std::filesystem::path& file, const OxtsRecord& record);

/// KITTI's convertOxtsToPose: the IMU poses T_IMU0<-IMUi (the first is the
/// identity). Position: Mercator projection with the scale cos(lat of the
/// first record), Earth radius 6378137 m; altitude as z. Orientation:
/// R = Rz(yaw) Ry(pitch) Rx(roll).
std::vector<Pose> oxts_to_poses(const std::vector<OxtsRecord>& records);
/// The inverse: the records whose oxts_to_poses are `imu_poses` (the first
/// must be the identity's frame: poses are relative to it) when the first
/// record is `origin`. For writing drives from known poses.
std::vector<OxtsRecord> poses_to_oxts(const std::vector<Pose>& imu_poses, const OxtsRecord& origin);

inline constexpr std::int64_t kNanosPerSecond = 1000000000;
/// Nanoseconds as seconds (a double holds about 0.2 us at today's epoch
/// times: subtract nanoseconds first where that matters).
[[nodiscard]] inline double nanos_to_seconds(std::int64_t nanos) { return static_cast<double>(nanos) / 1e9; }

/// A timestamps file: nanoseconds since 1970-01-01 00:00 of the file's clock
/// (the date taken as UTC), one per line, increasing; exact, so that times
/// of a drive relative to its first scan are those written. InputError
/// naming the file and the line for a malformed date or time, or a time
/// that does not increase. Empty lines are skipped.
std::vector<std::int64_t> parse_kitti_timestamps_ns(std::istream& in, const std::filesystem::path& file);
std::vector<std::int64_t> read_kitti_timestamps_ns(const std::filesystem::path& file);
/// Writes nanoseconds (or seconds, rounded to nanoseconds) since the epoch
/// as KITTI timestamp lines.
void write_kitti_timestamps_ns(const std::filesystem::path& file, const std::vector<std::int64_t>& nanos);
void write_kitti_timestamps(const std::filesystem::path& file, const std::vector<double>& seconds);

/// T_velo<-imu from calib_imu_to_velo.txt (R re-orthonormalised; InputError
/// when R or T is missing or R is not a rotation).
Pose parse_imu_to_velo(std::istream& in, const std::filesystem::path& file);
Pose read_imu_to_velo(const std::filesystem::path& file);
void write_imu_to_velo(const std::filesystem::path& file, const Pose& imu_to_velo);

}  // namespace saloam
