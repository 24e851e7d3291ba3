#pragma once
// The rings of a scan: which laser saw each point, and when in the sweep.
// Both the odometry's features (odometry/features.hpp) and the segmentation's
// range images (segmentation/range_projection.hpp) are built on them. A
// scan's rings come from what the sensor says about its points when it says
// it, else from the storage order, else from the elevation:
//  - the ring field (LabelledCloud::ring: PCD, PLY, PointCloud2 with a
//    `ring` field; the simulator's scans);
//  - the elevation angles of the sensor's lasers (a sensor profile's,
//    FeatureConfig::beam_elevations_deg);
//  - the storage order (a scan stored ring by ring, as KITTI's);
//  - the beam layout of the common sensors (HDL-64E, HDL-32E, VLP-16).
// Each returns point indices per ring, top ring first, each ring in sweep
// order (by `times`, the points' sweep times; a negative time marks a point
// on the sensor axis, left out).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

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

/// scan_rings() with the points' sweep times at hand: from the
/// ring field when the scan has one, else from the storage order when it is
/// ring by ring, else from the elevation: the sensor profile's lasers when
/// known, else the layout of config.num_beams.
RingIndices rings_from_times(const LabelledCloud& cloud, const std::vector<float>& times, const FeatureConfig& config);

/// Vertical layout of a spinning LiDAR, used to assign rings from elevation.
enum class BeamLayout { kHdl64, kHdl32, kVlp16 };

/// Number of rings of a layout (64, 32, 16).
int ring_count(BeamLayout layout);
/// Layout from `num_beams` (64/32/16), or detected from the elevation range
/// of the scan when num_beams is 0.
BeamLayout detect_beam_layout(const std::vector<Eigen::Vector3f>& points, int num_beams);
/// Ring of a point with elevation `elevation_deg`, or -1 outside the layout's
/// field of view. The HDL-64E has two blocks with different spacing: upper
/// +2.0..-8.33 deg at ~1/3 deg, lower -8.83..-24.9 deg at ~1/2 deg.
int ring_from_elevation(double elevation_deg, BeamLayout layout);

/// Time of a return within the sweep [s] from its azimuth, for a sensor that
/// starts the sweep at `start_azimuth_deg` and turns clockwise seen from above
/// (decreasing azimuth, as the Velodyne HDL-64E in KITTI) or counter-clockwise.
double sweep_time_from_azimuth(double azimuth_rad, const FeatureConfig& config);

/// Rings from the storage order. The simulator writes a scan ring by ring in
/// firing order (a ring ends where the sweep time jumps back); real KITTI
/// stores each ring counter-clockwise from azimuth 0 whatever the firing
/// order: when the sweep's own order does not split the scan into rings, the
/// sense is read from the steps between consecutive points and the seam from
/// the first point. Returns point indices per ring, or
/// nothing when the order does not look like rings (then rings come from the
/// elevation). expected_rings <= 0: unknown.
std::vector<std::vector<std::uint32_t>> rings_from_point_order(const LabelledCloud& cloud,
                                                              const FeatureConfig& config, int expected_rings);

/// Point indices per ring (top ring first), each ring in azimuth order: from the ring field when the cloud has one
/// (rings ordered by elevation), else from the storage order when the scan is
/// stored ring by ring (and config.ring_from_point_order), else from the
/// elevation angle: the nearest of config.beam_elevations_deg (the sensor
/// profile's lasers) when given, else the layout of config.num_beams. Points
/// in no ring (outside the field of view, invalid) are left out.
std::vector<std::vector<std::uint32_t>> scan_rings(const LabelledCloud& cloud, const FeatureConfig& config);

/// Ring of every point (-1 for none) and the sensor's number of rings, for
/// a range image: the rings of scan_rings() numbered from the top; when fewer
/// rings returned points than the sensor has (config.num_beams, else the
/// smallest of 16, 32, 64, 128 that holds them), the empty ones are placed
/// by the elevation gaps between the rings found, or above the top one.
struct PointRings {
  std::vector<std::int16_t> ring;
  int beams = 0;
};
PointRings point_rings(const LabelledCloud& cloud, const FeatureConfig& config);

}  // namespace saloam
