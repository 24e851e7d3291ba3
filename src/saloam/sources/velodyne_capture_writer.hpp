#pragma once
// Scans written as a Velodyne packet capture (what `saloam simulate --format
// velodyne-pcap` makes, so that tests make their own captures): the lasers
// decide the model (16: VLP-16, 32: HDL-32E, 64: HDL-64E), each scan's
// points go back into the firings of the sweep they were rendered from,
// and the firings into 1206-byte data packets (sensors/velodyne_packet.hpp)
// in Ethernet/IPv4/UDP frames to port 2368 (sensors/pcap_reader.hpp), each
// captured at its last firing's time: the sensor's packet rate.
//
// The sweep is the simulator's (sim/lidar.hpp): `azimuth_steps` columns a
// turn, column c at azimuth pi - 2 pi (c + 0.5) / steps (x forward, y left),
// fired at the scan's time + period (c + 0.5) / steps; a point's column is
// found from its azimuth, its laser from its ring (0 = top). What the
// packets cannot hold exactly: ranges are rounded to 2 mm (and must lie
// within 2 mm .. 131 m), azimuths to 0.01 deg, remission (0..1) to 1/255.
// Beside the capture, NAME.yaml holds the lasers' elevations as a
// velodyne_pointcloud calibration (channels in the model's firing order:
// VLP-16 and HDL-32E interleave their lasers from the bottom, the HDL-64E's
// upper block holds the top 32), which the reader finds there.
// A VLP-16 reads back with each laser turned by its firing delay (up to
// 0.125 deg at 0.2 deg per column), as a real VLP-16's points are: the
// simulator fires all lasers of a column at one azimuth.

#include <filesystem>
#include <vector>

#include "saloam/io/frame_source.hpp"
#include "saloam/sensors/velodyne_packet.hpp"

namespace saloam {

struct VelodyneSweepLayout {
  std::vector<double> elevation_deg;  ///< the lasers, top first (the rings)
  int azimuth_steps = 0;              ///< columns per turn
  double sweep_period = 0.1;          ///< [s]
};

/// The model of `lasers` lasers; ConfigError for a count no model has.
VelodyneModel velodyne_model_for(std::size_t lasers);

/// Writes every scan of `in` (with rings) into `capture` and its
/// calibration beside it (`capture` with .yaml). ConfigError for a layout
/// no model has; InputError naming the scan for points without rings.
void write_velodyne_capture(FrameSource& in, const VelodyneSweepLayout& layout, const std::filesystem::path& capture);

}  // namespace saloam
