#pragma once
// Scan Context (Kim and Kim, "Scan Context: Egocentric Spatial Descriptor for
// Place Recognition within 3D Point Cloud Map", IROS 2018): a polar grid of
// the maximum point height per (ring, sector) bin, compared with a
// column-shift cosine distance that makes it invariant to the sensor's yaw.
// The place-recognition baseline SGPR is compared with.

#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace saloam {

struct ScanContextConfig {
  int num_rings = 20;         ///< N_r radial bins
  int num_sectors = 60;       ///< N_s azimuth bins (6 degrees each)
  double max_range = 80.0;    ///< [m] points farther away are ignored
  double lidar_height = 2.0;  ///< [m] added to z so that ground-level bins are positive (as in the original)
};

struct ScanContext {
  Eigen::MatrixXf descriptor;  ///< rings x sectors, max height per bin (0 = empty)
  Eigen::VectorXf ring_key;    ///< mean of each ring: rotation-invariant, for retrieval
  Eigen::MatrixXf unit_columns;  ///< columns scaled to unit length (zero for empty columns)
};

/// Builds the descriptor of one scan (points in the sensor frame).
ScanContext make_scan_context(std::span<const Eigen::Vector3f> points, const ScanContextConfig& config = {});

/// The descriptor with its derived parts (ring key, unit columns) from the
/// max-height grid alone (what a saved map stores).
ScanContext scan_context_from_descriptor(Eigen::MatrixXf descriptor);

struct ScanContextMatch {
  double distance = 1.0;  ///< in [0, 2]; 0 = identical after the best shift (Eq. 6 of the paper)
  int shift = 0;          ///< sectors the candidate is rotated by for the best match
};

/// Column-shift distance: for every circular shift of the candidate's sectors,
/// the mean over columns non-empty in both of (1 - cosine similarity); the
/// minimum over all shifts (exhaustive, not the sector-key shortcut). Both
/// descriptors must have the same size. Returns distance 1 when no column is
/// non-empty in both.
ScanContextMatch scan_context_distance(const ScanContext& query, const ScanContext& candidate);

/// The `count` stored descriptors whose ring keys are nearest (Euclidean) to
/// the query's, among the first `searchable` entries; sorted by ring-key
/// distance. This is Scan Context's retrieval step before the exact distance
/// (exhaustive over the ring keys: 20 numbers per scan).
std::vector<std::size_t> ring_key_candidates(const ScanContext& query, std::span<const ScanContext> database,
                                             std::size_t searchable, std::size_t count);

}  // namespace saloam
