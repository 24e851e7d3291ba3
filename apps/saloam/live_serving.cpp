#include "live_serving.hpp"

#include <chrono>
#include <iostream>
#include <thread>

#include <fmt/format.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/viewer/viewer_scene.hpp"

namespace saloam::cli {

void ServeOptions::add_to(CLI::App& app) {
  app.add_flag("--serve", serve,
               "Show the run in the browser as it goes (trajectory, loops, newest scan, the map growing) at "
               "http://127.0.0.1:PORT/; a run that ends by itself keeps its page until Ctrl-C");
  app.add_option("--port", port, "Port for --serve (0: any free one)")->capture_default_str()->check(CLI::Range(0, 65535));
}

LiveServing::LiveServing(const std::string& title, const std::string& command, int port)
    : view_(std::make_shared<LiveView>(title, command)), server_(view_) {
  port_ = server_.start("127.0.0.1", port);
  std::cout << fmt::format("following the run at http://127.0.0.1:{}/\n", port_) << std::flush;
}

LiveServing::~LiveServing() {
  if (!ended_) view_->finish(LiveRunStatus::kFailed);
}

void LiveServing::show_map(const std::filesystem::path& folder) {
  view_->set_background(load_map_viewer_scene(folder).map);
}

FrameFollower LiveServing::follower() const {
  return [view = view_](const FinishedFrame& frame) {
    view->add_frame(frame.pose, frame.scan);
    if (frame.corrected) view->replace_poses(*frame.corrected);
    for (const auto& [query, match] : frame.loops) view->add_loop(query, match);
  };
}

void LiveServing::run_ended(bool interrupted) {
  ended_ = true;
  view_->finish(interrupted ? LiveRunStatus::kInterrupted : LiveRunStatus::kFinished);
  if (interrupted) return server_.stop();
  std::cout << fmt::format("the run is done; its page stays at http://127.0.0.1:{}/ until Ctrl-C\n", port_)
            << std::flush;
  while (!stop_requested()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  server_.stop();
  clear_stop();  // Ctrl-C is how the page ends after a complete run: not an interruption
  std::cout << "server stopped\n";
}

}  // namespace saloam::cli
