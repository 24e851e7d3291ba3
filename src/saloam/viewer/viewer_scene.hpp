#pragma once
// What the viewer shows, read from the output folder of `saloam slam` (and
// the sequence it ran on, for the ground truth and the scans):
//   map.ply                      the global semantic map (LiDAR frame, world = first processed frame)
//   poses_tum.txt                loop-closed trajectory (LiDAR frame)
//   poses_odometry_tum.txt       odometry trajectory (LiDAR frame)
//   loops.csv                    verified loop candidates (frames index the processed frames)
//   summary.json                 the sequence folder and the first processed frame
//   SEQ/poses.txt + calib.txt    ground truth, when present
//   SEQ/velodyne, SEQ/labels     the scans for the frame slider
// or from a saved map (`slam --save-map`, `merge`; docs/map_format.md), a
// folder with map.json: the keyframes' optimised poses as the trajectory
// (one per session), the loop edges of its pose graph (within a session and
// across sessions apart), the keyframes' feature clouds placed by their poses
// as the map, and each keyframe's features as the scan at the slider. A
// session that is not linked keeps its own frame (MapSession::linked).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/io/sequence.hpp"

namespace saloam {

struct ViewerOptions {
  std::size_t max_map_points = 1'000'000;         ///< map budget: the map is decimated to at most this many points
  std::size_t max_scan_points = 400'000;          ///< scans embedded in the page, all together
  std::size_t points_per_scan = 8'000;            ///< each scan is decimated to at most this many points
  std::optional<std::filesystem::path> sequence;  ///< sequence folder; default: the one in summary.json
  /// Instead of a sequence folder, the frames from memory (e.g. a simulator
  /// that wrote nothing to disk, as the demo's): the ground truth of the
  /// processed frames (LiDAR frame, world = the first of them) and scan
  /// `frame` (processed-frame index) in its own LiDAR frame.
  std::optional<std::vector<Pose>> ground_truth;
  std::function<LabelledCloud(std::size_t frame)> scans;
};

/// One drive of a saved map.
struct ViewerSession {
  std::string name;                  ///< its source (informational)
  std::vector<std::size_t> frames;   ///< its keyframes (indices of ViewerScene::loop_closed)
  bool linked = true;                ///< in the map frame (else in its own)
};

struct ViewerScene {
  std::filesystem::path run_dir;
  std::shared_ptr<const SequenceReader> sequence;          ///< for the ground truth and the scans, when found
  /// Scan of a processed frame (from the sequence or ViewerOptions::scans); empty when none is known.
  std::function<LabelledCloud(std::size_t frame)> scan_of;
  std::size_t first_frame = 0;                             ///< sequence frame of the first processed frame
  std::vector<Pose> loop_closed, odometry, ground_truth;   ///< LiDAR frame; ground truth may be empty
  std::vector<std::pair<std::size_t, std::size_t>> loops;  ///< accepted loops (query, match), processed-frame indices
  std::size_t loops_verified = 0;
  /// A saved map's drives (empty for a run folder, whose frames are one drive).
  std::vector<ViewerSession> sessions;
  /// A saved map's loop edges between keyframes of different sessions (in
  /// `loops`: those within a session).
  std::vector<std::pair<std::size_t, std::size_t>> cross_session_loops;
  /// The map a run saved (`slam --save-map`, as its summary.json names it);
  /// none for a saved map or a run that saved none.
  std::optional<std::filesystem::path> saved_map;
  LabelledCloud map;                 ///< decimated to the budget, sorted by class
  std::size_t map_points_total = 0;  ///< before decimation
};

/// Reads a run folder, or a saved map (a folder with map.json). InputError
/// (naming the file) when the folder, map.ply or poses_tum.txt is missing or
/// unreadable, when the sequence does not match, or when the map does not
/// read (read_map's checks).
ViewerScene load_viewer_scene(const std::filesystem::path& run_dir, const ViewerOptions& options = {});

/// True when `folder` holds a saved map (map.json) rather than a run's outputs.
bool is_map_folder(const std::filesystem::path& folder);

/// Reads a saved map. The map cloud takes at most options.max_map_points
/// points: each keyframe's features are decimated to an equal share as they
/// are read, one keyframe at a time. options.sequence, ground_truth and
/// scans do not apply (InputError when given).
ViewerScene load_map_viewer_scene(const std::filesystem::path& map_folder, const ViewerOptions& options = {});

/// At most `budget` points of `cloud`, an evenly spread deterministic random
/// subset (all of them when it fits), sorted by label.
LabelledCloud decimate_cloud(const LabelledCloud& cloud, std::size_t budget);

/// Scan `frame` (processed-frame index) of the scene's sequence in its own
/// LiDAR frame, decimated to `max_points`. InputError without a sequence or
/// for a frame out of range.
LabelledCloud load_viewer_scan(const ViewerScene& scene, std::size_t frame, std::size_t max_points);

/// Processed frames whose scans fit `options` (every k-th frame, evenly spread).
std::vector<std::size_t> embedded_scan_frames(const ViewerScene& scene, const ViewerOptions& options);

/// The accepted loops of a loops.csv written by `saloam slam` (query_frame,
/// match_frame, accepted columns); `verified` gets the number of rows.
std::vector<std::pair<std::size_t, std::size_t>> read_accepted_loops(const std::filesystem::path& file,
                                                                     std::size_t* verified = nullptr);

}  // namespace saloam
