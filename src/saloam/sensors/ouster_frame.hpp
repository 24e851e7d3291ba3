#pragma once
// Ouster lidar packets gathered into frames, and frames turned into points.
// Pure (no I/O): packet bytes in (ouster_packet.hpp), scans and clouds out.
//
// OusterFrameAssembler batches packets by frame id, as the manufacturer's
// SDK (FrameBatcher) does for packets that come in order: a column goes to
// its measurement id; a column whose status bit 0 is clear (not valid), or
// whose measurement id is beyond the frame, stays zero (fields, timestamp,
// status); a frame ends when it has all the packets its column window
// sends, or when a packet of a later frame id comes (packets of an earlier
// frame than the one being filled, or of one already finished, are dropped
// and counted). Frames are "staggered" as the sensor sends them: column u
// of row r was measured at column u's time, and the image a camera would
// show is destagger()'s.
//
// OusterXyzLut places a pixel as the SDK's XYZLut does (make_xyz_lut): for
// column u of W and row r, the encoder angle theta_e = 2 pi (1 - u / W),
// the beam's azimuth theta_a = -beam_azimuth_angles[r], its altitude
// phi = beam_altitude_angles[r]; the unit direction
//   d = (cos(theta_e + theta_a) cos phi, sin(theta_e + theta_a) cos phi, sin phi),
// the beam origin offset with n = beam_to_lidar(0,3) (lidar_origin_to_beam_origin_mm)
// and its z offset beam_to_lidar(2,3):
//   o = (n cos theta_e, n sin theta_e, beam_to_lidar(2,3)) - |n, z| d,
// a range r [mm] is at lidar_to_sensor * (r d + o), then scaled to metres.
// Points are in the sensor frame (x forward, z up, at the sensor's base).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/types.hpp"
#include "saloam/sensors/ouster_metadata.hpp"
#include "saloam/sensors/ouster_packet.hpp"

namespace saloam {

/// One frame of an Ouster sensor, staggered, columns by measurement id.
struct OusterScan {
  std::uint32_t frame_id = 0;
  std::uint32_t width = 0;   ///< columns_per_frame
  std::uint32_t height = 0;  ///< pixels_per_column
  std::vector<std::uint64_t> timestamp;       ///< [ns] per column; 0 where none came
  std::vector<std::uint16_t> measurement_id;  ///< per column; 0 where none came
  std::vector<std::uint32_t> status;          ///< per column; 0 where none came
  /// The profile's pixel fields but the raw words, each height x width row-major.
  std::vector<std::pair<OusterField, std::vector<std::uint32_t>>> fields;
  std::size_t packets = 0;        ///< packets batched
  std::size_t valid_columns = 0;  ///< columns filled

  [[nodiscard]] const std::vector<std::uint32_t>* field(OusterField f) const;
  /// The first filled column's timestamp [ns], as the SDK's frame timestamp.
  [[nodiscard]] std::optional<std::uint64_t> first_valid_timestamp() const;
};

class OusterFrameAssembler {
 public:
  explicit OusterFrameAssembler(const OusterMetadata& metadata);

  /// Adds one lidar packet's payload; the frames it finishes go to `done`
  /// (none, one, or two when a one-packet frame follows another). A packet
  /// of the wrong size is counted (bad_packets) and left out.
  void add(std::span<const std::uint8_t> packet, std::vector<OusterScan>& done);
  /// The frame being filled, if any (at the end of a capture).
  std::optional<OusterScan> finish();

  [[nodiscard]] const OusterPacketFormat& format() const { return format_; }
  [[nodiscard]] std::size_t bad_packets() const { return bad_packets_; }
  [[nodiscard]] std::size_t dropped_packets() const { return dropped_packets_; }

 private:
  void start(std::uint32_t frame_id);
  void batch(std::span<const std::uint8_t> packet);
  void finalize(std::vector<OusterScan>& done);

  OusterPacketFormat format_;
  std::uint32_t width_ = 0;
  std::uint32_t packets_per_frame_ = 0;
  std::optional<OusterScan> current_;
  std::optional<std::uint32_t> finished_id_;
  std::size_t bad_packets_ = 0;
  std::size_t dropped_packets_ = 0;
};

/// `image` (height x width row-major, staggered) as the sensor's picture:
/// row r shifted right by pixel_shift_by_row[r] columns, wrapping.
template <class T>
[[nodiscard]] std::vector<T> destagger(std::span<const T> image, std::uint32_t width, std::span<const int> shifts) {
  std::vector<T> out(image.size());
  const auto w = static_cast<long>(width);
  for (std::size_t r = 0; r < shifts.size(); ++r) {
    const long offset = ((shifts[r] % w) + w) % w;
    for (long u = 0; u < w; ++u) out[r * width + static_cast<std::size_t>((u + offset) % w)] = image[r * width + static_cast<std::size_t>(u)];
  }
  return out;
}

class OusterXyzLut {
 public:
  explicit OusterXyzLut(const OusterMetadata& metadata);
  /// Pixel (row, column) at `range_mm` [mm], in metres in the sensor frame.
  [[nodiscard]] Eigen::Vector3d point(std::uint32_t row, std::uint32_t column, double range_mm) const {
    const std::size_t i = static_cast<std::size_t>(row) * width_ + column;
    return range_mm * direction_[i] + offset_[i];
  }

 private:
  std::uint32_t width_ = 0;
  std::vector<Eigen::Vector3d> direction_;  ///< per pixel, sensor frame, [m per mm]
  std::vector<Eigen::Vector3d> offset_;     ///< per pixel, sensor frame, [m]
};

/// The points of a frame: every pixel with a first-return range (> 0),
/// row (ring) by row, in the sensor frame [m]; remission = REFLECTIVITY /
/// `reflectivity_divisor`; ring = the row (beam 0 the highest); time = its
/// column's timestamp less `frame_time_ns` [s]. Labels none.
[[nodiscard]] LabelledCloud ouster_cloud(const OusterScan& scan, const OusterXyzLut& lut, std::uint64_t frame_time_ns,
                                         float reflectivity_divisor);

}  // namespace saloam
