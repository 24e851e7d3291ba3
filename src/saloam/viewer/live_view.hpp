#pragma once
// What `--serve` shows of a run while it goes on (`saloam slam|odom ...
// --serve`): the trajectory, the loops, the newest scan and a map that grows
// as the run drives. The run's thread adds each frame; the viewer server's
// threads read (every member is thread-safe). The page polls:
//   state_json   the poses the page lacks (all of them again after loop
//                closure moved earlier frames: a new revision), the loops,
//                counts and whether the run is still going
//   map_chunks   the map's pieces the page lacks
//   latest_scan  the newest scan
//   background   a map the run happens in (localisation's saved map), once
// The map is pieces of scans (a decimated scan every `chunk_spacing` metres
// travelled), each kept in its own frame's LiDAR frame and placed by that
// frame's current pose, so that loop closure moves the map with the
// trajectory. All poses: T_world<-LiDAR, world = the run's first frame.

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

struct LiveViewOptions {
  double chunk_spacing = 2.0;              ///< [m] travelled between the scans kept for the map
  std::size_t points_per_chunk = 3'000;    ///< each kept scan is decimated to at most this many points
  std::size_t scan_points = 8'000;         ///< the newest scan, decimated to at most this many points
  std::size_t max_map_points = 2'000'000;  ///< beyond this many, the spacing doubles (and again at twice as many)
};

enum class LiveRunStatus { kRunning, kFinished, kInterrupted, kFailed };

class LiveView {
 public:
  /// `title`: what the page calls the run (e.g. the source).
  LiveView(std::string title, std::string command, const LiveViewOptions& options = {});

  /// A map the run happens in (a localisation's saved map, in the frame of
  /// the run's poses), shown under the run's own pieces; decimated by the caller.
  void set_background(const LabelledCloud& map);
  /// The run's next frame: its pose now and its scan (LiDAR frame).
  void add_frame(const Pose& pose, const LabelledCloud& scan);
  /// Loop closure moved earlier frames: the pose of every frame added so
  /// far, in order. std::invalid_argument when the count differs.
  void replace_poses(std::vector<Pose> poses);
  /// An accepted loop between two frames added so far (processed-frame indices).
  void add_loop(std::size_t query, std::size_t match);
  /// The run has ended (the page stops polling for frames).
  void finish(LiveRunStatus status);

  /// The state as JSON for a page that holds the first `known_frames` poses
  /// of `revision`: the poses it lacks (from "first"; every pose from 0 when
  /// its revision is not the current one), as base64 float32 [R|t] rows.
  [[nodiscard]] std::string state_json(std::uint64_t revision, std::size_t known_frames) const;
  /// The map pieces from `first` on: per piece, uint32 frame and uint32
  /// point count (little-endian), then its points encoded as a scan
  /// (point_encoding.hpp: int16 xyz, then one class byte a point).
  [[nodiscard]] std::string map_chunks(std::size_t first) const;
  /// The newest scan: uint32 frame, then the scan encoding; empty before the first frame.
  [[nodiscard]] std::string latest_scan() const;
  /// The background map in the map encoding (point_encoding.hpp), its
  /// origin and step in state_json's "background"; empty when none.
  [[nodiscard]] std::string background() const;

  [[nodiscard]] std::size_t frames() const;
  [[nodiscard]] std::size_t chunks() const;
  [[nodiscard]] std::size_t map_points() const;
  [[nodiscard]] LiveRunStatus status() const;

 private:
  struct Chunk {
    std::uint32_t frame = 0;
    std::string points;  ///< encode_scan()
  };
  [[nodiscard]] bool chunk_due(const Pose& pose) const;
  void keep_chunk(std::size_t frame, const LabelledCloud& scan);

  const std::string title_, command_;
  const LiveViewOptions options_;
  mutable std::mutex mutex_;
  std::vector<Pose> poses_;
  std::uint64_t revision_ = 0;
  std::vector<std::pair<std::size_t, std::size_t>> loops_;
  std::vector<Chunk> chunks_;
  std::size_t map_points_ = 0;
  double spacing_ = 0;         ///< current chunk spacing [m]
  double travelled_ = 0;       ///< [m] along the poses as added
  double chunk_travelled_ = 0; ///< travelled_ at the last chunk
  std::string latest_scan_;
  std::string background_;
  std::vector<double> background_origin_;  ///< x, y, z [m]
  double background_scale_ = 0;            ///< [m] a step
  LiveRunStatus status_ = LiveRunStatus::kRunning;
};

}  // namespace saloam
