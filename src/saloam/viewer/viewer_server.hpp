#pragma once
// `saloam view --serve`: the viewer page from a local HTTP server
// (cpp-httplib), for maps too large to embed. Routes:
//   /            the page (ViewerDataSource::kServer)
//   /map.bin     the decimated map (point_encoding.hpp)
//   /scan/N      scan N (processed-frame index), loaded from the sequence on demand
// Or, for a run in progress (`saloam slam|odom ... --serve`, live_view.hpp):
//   /                                  the live page, which polls
//   /live.json?revision=R&frames=N     LiveView::state_json(R, N)
//   /live/map?from=K                   LiveView::map_chunks(K)
//   /live/scan                         LiveView::latest_scan()
//   /live/background                   LiveView::background()
// Only requests whose Host names the loopback and the port are answered (DNS
// rebinding); error bodies are short and name no file.

#include <memory>
#include <string>
#include <string_view>

#include "saloam/viewer/live_view.hpp"
#include "saloam/viewer/viewer_scene.hpp"

namespace saloam {

/// Whether a request's Host header names this server on the loopback:
/// 127.0.0.1:PORT, localhost:PORT or [::1]:PORT (anything else, e.g. a
/// rebound DNS name, is refused with 403).
bool viewer_host_allowed(std::string_view host, int port);

class ViewerServer {
 public:
  /// Prepares the page and the map; InputError as write_viewer_page.
  ViewerServer(ViewerScene scene, const ViewerOptions& options);
  /// Serves the live page of a run that adds its frames to `live`.
  /// InputError when saloam was built without three.js.
  explicit ViewerServer(std::shared_ptr<const LiveView> live);
  ~ViewerServer();
  ViewerServer(const ViewerServer&) = delete;
  ViewerServer& operator=(const ViewerServer&) = delete;

  /// Binds `host`:`port` (port 0: any free port), answers from its own
  /// threads from now until stop(), and returns the port. InputError naming
  /// the address when it is taken; std::logic_error when already started.
  int start(const std::string& host, int port);
  /// Stops answering and waits until the server's threads are done; nothing
  /// when not started. The destructor stops it too.
  void stop();
  /// Between start() and stop(), unless listening failed.
  [[nodiscard]] bool running() const;
  [[nodiscard]] std::size_t page_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace saloam
