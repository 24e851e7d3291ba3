#pragma once
// `--serve` of `saloam slam`, `odom` and `localize`: the live page of the run at
// http://127.0.0.1:PORT/ while the run goes on (viewer/live_view.hpp). The
// server answers from its own threads; the run feeds it through follower().
// A run that ends by itself keeps its page until Ctrl-C (as `saloam view
// --serve`); one that Ctrl-C or an error ended stops the server at once.

#include <filesystem>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "saloam/runs/finished_frame.hpp"
#include "saloam/viewer/live_view.hpp"
#include "saloam/viewer/viewer_server.hpp"

namespace saloam::cli {

struct ServeOptions {
  bool serve = false;
  int port = 8080;
  /// --serve and --port.
  void add_to(CLI::App& app);
};

class LiveServing {
 public:
  /// Binds 127.0.0.1:port (0: any free port; InputError when taken), says
  /// the address and starts answering. `title`: the run's source.
  LiveServing(const std::string& title, const std::string& command, int port);
  /// Stops the server (the run failed when run_ended() was not called).
  ~LiveServing();
  LiveServing(const LiveServing&) = delete;
  LiveServing& operator=(const LiveServing&) = delete;

  /// Shows the saved map at `folder` under the run (`localize`): its
  /// keyframes' features, decimated as `saloam view` decimates them.
  void show_map(const std::filesystem::path& folder);
  /// What the run calls after each frame.
  [[nodiscard]] FrameFollower follower() const;
  /// The run has ended and written its outputs: after an interruption the
  /// server stops now; otherwise the page stays until Ctrl-C, which then
  /// ends the command normally (not an interruption).
  void run_ended(bool interrupted);

 private:
  std::shared_ptr<LiveView> view_;
  ViewerServer server_;  ///< stops when destroyed
  int port_ = 0;
  bool ended_ = false;
};

}  // namespace saloam::cli
