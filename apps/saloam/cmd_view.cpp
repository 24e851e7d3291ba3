// `saloam view`: the map, the trajectories and the loops of a `saloam slam`
// run, or the sessions of a saved map, in the browser. Writes one self-contained page (src/saloam/viewer/), or
// with --serve serves it from 127.0.0.1 and loads scans on demand.

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <thread>

#include <fmt/format.h>

#include "command.hpp"
#include "saloam/core/cancellation.hpp"
#include "saloam/core/output_folder.hpp"
#include "saloam/viewer/viewer_page.hpp"
#include "saloam/viewer/viewer_server.hpp"

namespace saloam::cli {
namespace {

struct ViewOptions {
  std::string run_dir;
  std::string page;
  std::string sequence;
  ViewerOptions viewer;
  bool serve = false;
  int port = 8080;
};

ViewerOptions viewer_options(const ViewOptions& options) {
  ViewerOptions viewer = options.viewer;
  if (!options.sequence.empty()) viewer.sequence = options.sequence;
  return viewer;
}

/// Points from a run to the map it saved (`slam --save-map`), which has a
/// page of its own.
void print_saved_map(const std::filesystem::path& map) {
  if (is_map_folder(map)) {
    std::cout << fmt::format("this run saved a map: saloam view {}\n", map.string());
  } else {
    std::cout << fmt::format("this run saved a map to {}, which holds no map now\n", map.string());
  }
}

/// Writes the page while no run writes the run folder (its lock, joined:
/// the page is added to the run's record when it lies in the folder); a
/// saved map's page goes beside the map.
int write_page(const ViewOptions& options) {
  const std::filesystem::path page =
      options.page.empty() ? default_viewer_page(options.run_dir) : std::filesystem::path(options.page);
  // A run's folder takes its page (the folder is joined); a saved map and a sequence are inputs only.
  PathRules()
      .input("--sequence", options.sequence)
      .input("MAP", is_map_folder(options.run_dir) ? std::filesystem::path(options.run_dir) : std::filesystem::path())
      .output("--out", page)
      .check();
  std::error_code error;
  std::unique_ptr<OutputFolder> lock;
  if (std::filesystem::is_directory(options.run_dir, error) && !is_map_folder(options.run_dir)) {
    lock.reset(new OutputFolder(OutputFolder::join(options.run_dir, "view")));
  }
  const ViewerPageStats s = write_viewer_page(options.run_dir, page, viewer_options(options));
  if (s.sessions > 0) {
    std::cout << fmt::format(
        "wrote {} ({:.1f} MB): {} of {} map points, {} keyframes in {} sessions, {} loops within sessions, {} across, "
        "{} scans of {} points in all\n",
        page.string(), static_cast<double>(s.bytes) / 1e6, s.map_points, s.map_points_total, s.frames, s.sessions,
        s.loops, s.cross_session_loops, s.scans, s.scan_points);
  } else {
    std::cout << fmt::format(
        "wrote {} ({:.1f} MB): {} of {} map points, {} frames{}, {} loops, {} scans of {} points in all\n",
        page.string(), static_cast<double>(s.bytes) / 1e6, s.map_points, s.map_points_total, s.frames,
        s.ground_truth ? " with ground truth" : "", s.loops, s.scans, s.scan_points);
  }
  std::cout << fmt::format("open file://{}\n", std::filesystem::absolute(page).lexically_normal().string());
  if (s.saved_map) print_saved_map(*s.saved_map);
  return 0;
}

/// Serves until Ctrl-C (the stop flag of main's signal handler).
int serve(const ViewOptions& options) {
  const ViewerOptions viewer = viewer_options(options);
  ViewerServer server(load_viewer_scene(options.run_dir, viewer), viewer);
  const int port = server.start("127.0.0.1", options.port);
  std::cout << fmt::format("serving {} at http://127.0.0.1:{}/ (Ctrl-C stops)\n", options.run_dir, port) << std::flush;
  while (!stop_requested() && server.running()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  server.stop();
  stop_flag().store(false);  // Ctrl-C is how a server ends: not an interruption
  std::cout << "server stopped\n";
  return 0;
}

const CommandRegistration kRegistration{Command{
    "view", "3D viewer in the browser: the semantic map, trajectories, loops and scans of a `saloam slam` run or of a saved map's "
    "sessions",
    27,
    [](CLI::App& app) {
      auto options = std::make_shared<ViewOptions>();
      app.add_option("OUT_DIR", options->run_dir,
                     "Output folder of `saloam slam` (map.ply, poses_tum.txt, loops.csv), or a saved map (map.json)")
          ->required();
      app.add_option("--out", options->page, "Page to write (default OUT_DIR/view.html; for a map MAP.view.html beside it)");
      app.add_option("--max-points", options->viewer.max_map_points, "Map point budget: decimated to at most this many")
          ->capture_default_str()
          ->check(non_negative_integer())
          ->check(positive_number());
      app.add_option("--scan-points", options->viewer.points_per_scan, "Points per scan shown at the slider")
          ->capture_default_str()
          ->check(non_negative_integer());
      app.add_option("--max-scan-points", options->viewer.max_scan_points,
                     "Budget of the scans embedded in the page, all together (0: none)")
          ->capture_default_str()
          ->check(non_negative_integer());
      app.add_option("--sequence", options->sequence, "Sequence folder (default: the one recorded in summary.json; not for a map)");
      app.add_flag("--serve", options->serve, "Serve the page from 127.0.0.1 instead, scans loaded on demand");
      app.add_option("--port", options->port, "Port for --serve (0: any free one)")
          ->capture_default_str()
          ->check(CLI::Range(0, 65535));
      return [options] { return options->serve ? serve(*options) : write_page(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
