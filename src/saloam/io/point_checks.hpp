#pragma once
// The checks every point reader makes, in one place (KITTI .bin and KITTI raw
// scans, PCD, PLY, ROS PointCloud2), each counted and warned once per file
// (issue #39):
//   coordinates  non-finite, or beyond kMaxScanCoordinate along an axis:
//                the point is dropped
//   ring         not within 0..kMaxSensorLasers-1 (the most lasers a sensor
//                profile may list): the point is dropped (its beam is unknown);
//                once the sensor profile is known (sources/sensor_rings_source.hpp),
//                at or beyond its laser count: dropped too
//   time         relative to the scan's timestamp (which may be the sweep's
//                start, middle or end, so a time may be negative): non-finite
//                -> 0, beyond +-kMaxSweepSeconds (the longest sweep a sensor
//                profile may state) -> clamped to it; the point itself is
//                good, its de-skewing would extrapolate without bound
//   byte order   binary records whose stated byte order reads as implausible
//                coordinates while the other order reads as plausible ones:
//                refused, naming the order that fits

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string_view>
#include <vector>

#include "saloam/core/sensor_profile.hpp"

namespace saloam {

struct PointField;
struct FieldRoles;

/// A scan's coordinates are in the sensor frame: a point farther than this
/// along any axis (metres; no LiDAR sees 10 km) is not a measurement.
inline constexpr float kMaxScanCoordinate = 1.0e4F;
/// Per-point times [s] from the scan's timestamp beyond this (either way) are not of its sweep.
inline constexpr double kMaxSweepSeconds = 10.0;
/// Ring numbers at or beyond this fit no sensor (the most lasers a sensor profile may list).
inline constexpr double kMaxRings = static_cast<double>(kMaxSensorLasers);

/// What the checks found in one file.
struct PointCheckCounts {
  std::size_t nonfinite = 0;          ///< dropped: NaN/Inf coordinates
  std::size_t out_of_range = 0;       ///< dropped: a coordinate beyond kMaxScanCoordinate
  std::size_t bad_ring = 0;           ///< dropped: a ring outside 0..kMaxRings-1
  std::size_t ring_beyond_sensor = 0; ///< dropped: a ring at or beyond sensor_lasers
  std::size_t sensor_lasers = 0;      ///< the sensor profile's laser count checked against (0: none)
  std::size_t time_nonfinite = 0;     ///< set to 0
  std::size_t time_before_sweep = 0;  ///< below -kMaxSweepSeconds: set to it
  std::size_t time_after_sweep = 0;   ///< beyond kMaxSweepSeconds: set to it
  [[nodiscard]] std::size_t dropped() const { return nonfinite + out_of_range + bad_ring + ring_beyond_sensor; }
};

/// Whether a point with these coordinates is kept; counts the reason when not.
[[nodiscard]] bool keep_coordinates(double x, double y, double z, PointCheckCounts& counts);
/// Whether a point with this ring value is kept; counts it when not.
[[nodiscard]] bool keep_ring(double ring, PointCheckCounts& counts);
/// Whether a point with this ring is kept by a sensor of `lasers` lasers
/// (rings 0..lasers-1); counts it when not.
[[nodiscard]] bool keep_sensor_ring(std::uint16_t ring, std::size_t lasers, PointCheckCounts& counts);
/// A per-point time [s from the scan's timestamp] clamped into +-kMaxSweepSeconds (non-finite: 0), counted when it was not.
[[nodiscard]] float checked_time(double seconds, PointCheckCounts& counts);

/// One warning per kind of problem found, naming the file and how many of
/// `points_in_file` points it touched. Non-finite coordinates are a debug
/// message when `nonfinite_marks_missing` (organised clouds mark missing returns with NaN).
void warn_point_checks(const std::filesystem::path& file, std::size_t points_in_file, const PointCheckCounts& counts,
                       bool nonfinite_marks_missing = false);

/// Binary records: InputError naming `file` when the coordinates read in the
/// stated order are mostly implausible (non-finite, beyond kMaxScanCoordinate,
/// or tiny non-zero values such as a swapped float gives) while the other
/// order reads as plausible ones. `record_at(i)` is record i of `records`;
/// up to 1024 records are sampled. Only floating-point coordinates are judged.
void check_byte_order(std::size_t records, const std::function<const std::byte*(std::size_t)>& record_at,
                      const std::vector<PointField>& fields, const FieldRoles& roles, bool big_endian,
                      const std::filesystem::path& file);

}  // namespace saloam
