#pragma once
// The viewer page: one HTML file with three.js, the map, the trajectories,
// the loops and a subset of the scans inside (it opens from disk, with no
// server and no network), or the same page for ViewerServer, which sends the
// map and any scan on demand.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include "saloam/viewer/viewer_scene.hpp"

namespace saloam {

enum class ViewerDataSource {
  kEmbedded,  ///< everything inside the page
  kServer,    ///< the map from ./map.bin and scans from ./scan/N (ViewerServer)
};

struct ViewerPageStats {
  std::size_t bytes = 0;
  std::size_t map_points = 0;        ///< in the page (after decimation)
  std::size_t map_points_total = 0;  ///< in map.ply
  std::size_t frames = 0;
  std::size_t loops = 0;        ///< accepted loop edges drawn (a saved map: those within a session)
  std::size_t cross_session_loops = 0;  ///< a saved map's loop edges between sessions
  std::size_t sessions = 0;     ///< a saved map's sessions (0: a run folder)
  std::size_t scans = 0;        ///< embedded scans
  std::size_t scan_points = 0;  ///< in the embedded scans, all together
  bool ground_truth = false;
  std::optional<std::filesystem::path> saved_map;  ///< a run's saved map (ViewerScene::saved_map)
};

/// True when saloam was built with three.js (Debian's libjs-three).
bool viewer_has_three_js();

/// The page's HTML. InputError when saloam was built without three.js.
std::string viewer_page(const ViewerScene& scene, const ViewerOptions& options, ViewerDataSource source,
                        ViewerPageStats* stats = nullptr);

/// The page of a run in progress (ViewerServer with a LiveView), which asks
/// the server for news every `poll_ms`. InputError when saloam was built
/// without three.js.
std::string live_viewer_page(int poll_ms);

/// Where `saloam view FOLDER` writes its page by default: FOLDER/view.html
/// for a run folder; beside a saved map, MAP.view.html (the map folder holds
/// only the map: write_map replaces it whole).
std::filesystem::path default_viewer_page(const std::filesystem::path& folder);

/// Reads the output folder of `saloam slam` (or a saved map) and writes its
/// self-contained page to `page` (the demo and `saloam view` call this). InputError when
/// `page` exists and is not a viewer page: it never replaces another file.
ViewerPageStats write_viewer_page(const std::filesystem::path& run_dir, const std::filesystem::path& page,
                                  const ViewerOptions& options = {});

}  // namespace saloam
