#pragma once
// Rings of a scan from what the sensor says about its points, for
// extract_features()/scan_rings() (features.hpp), which fall back to the
// storage order and the elevation layouts when these do not apply:
//  - the ring field (LabelledCloud::ring: PCD, PLY, PointCloud2 with a
//    `ring` field; the simulator's scans);
//  - the elevation angles of the sensor's lasers (a sensor profile's,
//    FeatureConfig::beam_elevations_deg).
// Each returns point indices per ring, top ring first, each ring in sweep
// order (by `times`, the points' sweep times; a negative time marks a point
// on the sensor axis, left out).

#include <cstdint>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"

namespace saloam {

using RingIndices = std::vector<std::vector<std::uint32_t>>;

/// One ring per distinct value of cloud.ring (cloud.has_rings()), ordered
/// by the rings' mean elevation, highest first: drivers number their lasers
/// either way (Velodyne's ring 0 is the lowest, Ouster's the highest).
RingIndices rings_from_ring_field(const LabelledCloud& cloud, const std::vector<float>& times);

/// One ring per laser of `elevation_deg` (top first, decreasing): each point
/// goes to the laser of the nearest elevation; points more than half a
/// laser spacing beyond the top or bottom laser are left out.
RingIndices rings_from_laser_elevations(const LabelledCloud& cloud, const std::vector<float>& times,
                                        const std::vector<double>& elevation_deg);

/// Each point's time in the sweep [s] from its azimuth (the sweep model of
/// `config`), -1 for a point on the sensor axis; points are independent, so
/// with `parallel` blocks of them go to the threads (same output).
std::vector<float> point_sweep_times(const LabelledCloud& cloud, const FeatureConfig& config, bool parallel);

/// scan_rings() (features.hpp) with the points' sweep times at hand: from the
/// ring field when the scan has one, else from the storage order when it is
/// ring by ring, else from the elevation: the sensor profile's lasers when
/// known, else the layout of config.num_beams.
RingIndices rings_from_times(const LabelledCloud& cloud, const std::vector<float>& times, const FeatureConfig& config);

}  // namespace saloam
