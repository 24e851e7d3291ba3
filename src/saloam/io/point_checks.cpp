#include "saloam/io/point_checks.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"
#include "saloam/io/point_fields.hpp"

namespace saloam {

bool keep_coordinates(double x, double y, double z, PointCheckCounts& counts) {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
    ++counts.nonfinite;
    return false;
  }
  if (std::abs(x) > kMaxScanCoordinate || std::abs(y) > kMaxScanCoordinate || std::abs(z) > kMaxScanCoordinate) {
    ++counts.out_of_range;
    return false;
  }
  return true;
}

bool keep_ring(double ring, PointCheckCounts& counts) {
  if (std::isfinite(ring) && ring >= 0.0 && ring < kMaxRings) return true;
  ++counts.bad_ring;
  return false;
}

bool keep_sensor_ring(std::uint16_t ring, std::size_t lasers, PointCheckCounts& counts) {
  counts.sensor_lasers = lasers;
  if (ring < lasers) return true;
  ++counts.ring_beyond_sensor;
  return false;
}

float checked_time(double seconds, PointCheckCounts& counts) {
  if (!std::isfinite(seconds)) {
    ++counts.time_nonfinite;
    return 0.0F;
  }
  if (seconds < -kMaxSweepSeconds) {
    ++counts.time_before_sweep;
    return static_cast<float>(-kMaxSweepSeconds);
  }
  if (seconds > kMaxSweepSeconds) {
    ++counts.time_after_sweep;
    return static_cast<float>(kMaxSweepSeconds);
  }
  return static_cast<float>(seconds);
}

void warn_point_checks(const std::filesystem::path& file, std::size_t points_in_file, const PointCheckCounts& counts,
                       bool nonfinite_marks_missing) {
  const std::string name = file.string();
  if (counts.nonfinite > 0) {
    const auto level = nonfinite_marks_missing ? spdlog::level::debug : spdlog::level::warn;
    spdlog::log(level, "{}: dropped {} of {} points with NaN/Inf coordinates", name, counts.nonfinite, points_in_file);
  }
  if (counts.out_of_range > 0) {
    spdlog::warn("{}: dropped {} of {} points with a coordinate beyond {:g} m", name, counts.out_of_range,
                 points_in_file, kMaxScanCoordinate);
  }
  if (counts.bad_ring > 0) {
    spdlog::warn("{}: dropped {} of {} points with a ring outside 0..{:g}", name, counts.bad_ring, points_in_file,
                 kMaxRings - 1);
  }
  if (counts.ring_beyond_sensor > 0) {
    spdlog::warn("{}: dropped {} of {} points with a ring at or beyond the sensor's {} lasers (0..{})", name,
                 counts.ring_beyond_sensor, points_in_file, counts.sensor_lasers, counts.sensor_lasers - 1);
  }
  if (counts.time_nonfinite > 0) {
    spdlog::warn("{}: {} of {} points have a NaN/Inf time, taken as the scan's timestamp", name,
                 counts.time_nonfinite, points_in_file);
  }
  if (counts.time_before_sweep + counts.time_after_sweep > 0) {
    spdlog::warn("{}: {} of {} points have a time more than {:g} s from the scan's timestamp ({} before, {} after), "
                 "clamped to +-{:g} s",
                 name, counts.time_before_sweep + counts.time_after_sweep, points_in_file, kMaxSweepSeconds,
                 counts.time_before_sweep, counts.time_after_sweep, kMaxSweepSeconds);
  }
}

namespace {

bool plausible(double v) {
  // A float32 written in one byte order and read in the other is mostly
  // non-finite, huge, or a denormal-sized value: no coordinate of a LiDAR.
  return v == 0.0 || (std::isfinite(v) && std::abs(v) <= kMaxScanCoordinate && std::abs(v) >= 1e-6);
}

}  // namespace

void check_byte_order(std::size_t records, const std::function<const std::byte*(std::size_t)>& record_at,
                      const std::vector<PointField>& fields, const FieldRoles& roles, bool big_endian,
                      const std::filesystem::path& file) {
  const PointField* axes[] = {&fields[roles.x], &fields[roles.y], &fields[roles.z]};
  for (const PointField* f : axes) {
    if (!is_floating(f->type)) return;
  }
  if (records == 0) return;
  constexpr std::size_t kSamples = 1024;
  const std::size_t step = std::max<std::size_t>(1, records / kSamples);
  std::size_t sampled = 0, as_stated = 0, swapped = 0;
  for (std::size_t i = 0; i < records; i += step) {
    const std::byte* record = record_at(i);
    ++sampled;
    bool stated_ok = true, swapped_ok = true;
    for (const PointField* f : axes) {
      stated_ok = stated_ok && plausible(read_scalar(record + f->offset, f->type, big_endian));
      swapped_ok = swapped_ok && plausible(read_scalar(record + f->offset, f->type, !big_endian));
    }
    as_stated += stated_ok;
    swapped += swapped_ok;
  }
  if (2 * as_stated < sampled && 10 * swapped >= 9 * sampled) {
    throw InputError(file, fmt::format("the data is {} although the header says {}: {} of {} sampled points are "
                                       "plausible as stated, {} in the other byte order (correct the header)",
                                       big_endian ? "little-endian" : "big-endian",
                                       big_endian ? "big-endian" : "little-endian", as_stated, sampled, swapped));
  }
}

}  // namespace saloam
