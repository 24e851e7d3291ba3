#include "saloam/viewer/viewer_server.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"
#include "saloam/viewer/point_encoding.hpp"
#include "saloam/viewer/viewer_page.hpp"

// After Eigen: httplib.h includes <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

namespace saloam {

namespace {
// Idle connections (a browser's speculative ones, a client that connects and
// sends nothing) each hold a worker until the keep-alive timeout: many
// workers and a short wait keep a handful of them from stalling the page.
constexpr std::size_t kWorkerThreads = 64;
constexpr time_t kKeepAliveSeconds = 2;
constexpr time_t kReadSeconds = 5;
constexpr time_t kWriteSeconds = 10;
// The viewer takes no request bodies: a larger one is answered 413 and
// skipped, never buffered (httplib's default buffers any size).
constexpr std::size_t kMaxRequestBodyBytes = 64 * 1024;
// How often the live page asks for the run's news.
constexpr int kLivePollMs = 500;
}  // namespace

struct ViewerServer::Impl {
  ViewerScene scene;
  ViewerOptions options;
  std::shared_ptr<const LiveView> live;  ///< a run in progress instead of a scene
  std::string page;
  std::string map_bytes;
  httplib::Server server;
  int port = 0;  ///< bound port, for the Host check
  std::thread listener;  ///< runs server.listen_after_bind() from start() to stop()
  std::atomic<bool> listen_returned{false};

  void configure();
  void add_common_routes();
  void add_routes();
  void add_live_routes();
  void send_scan(const httplib::Request& request, httplib::Response& response) const;
};

namespace {

/// A query parameter as a number (0 when absent); nullopt when it is not one.
std::optional<std::uint64_t> number_parameter(const httplib::Request& request, const char* name) {
  if (!request.has_param(name)) return 0;
  const std::string text = request.get_param_value(name);
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size() || text.size() > 19) return std::nullopt;
  return value;
}

void bad_parameter(httplib::Response& response, const char* name) {
  response.status = 400;
  response.set_content(fmt::format("{}: not a number\n", name), "text/plain");
}

}  // namespace

bool viewer_host_allowed(std::string_view host, int port) {
  const std::string suffix = fmt::format(":{}", port);
  if (host.size() <= suffix.size() || host.substr(host.size() - suffix.size()) != suffix) return false;
  std::string name(host.substr(0, host.size() - suffix.size()));
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  return name == "127.0.0.1" || name == "localhost" || name == "[::1]";
}

void ViewerServer::Impl::add_common_routes() {
  // DNS rebinding: a page of another site whose name now resolves to
  // 127.0.0.1 sends its own name as Host. Only the loopback names pass.
  // Bounded answers: httplib answers every byte range of a request, each
  // with the whole body behind it (2,650 ranges of the page made 2.4 GB),
  // so a request for more than one range is refused (416); the pages ask for none.
  server.set_pre_routing_handler([this](const httplib::Request& request, httplib::Response& response) {
    if (!viewer_host_allowed(request.get_header_value("Host"), port)) {
      response.status = 403;
      response.set_content("forbidden: the viewer answers only to 127.0.0.1, localhost or [::1] with its port\n",
                           "text/plain");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (request.ranges.size() > 1) {
      response.status = 416;
      response.set_content("one byte range at most\n", "text/plain");
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  server.set_error_handler([](const httplib::Request&, httplib::Response& response) {
    if (response.body.empty()) response.set_content(fmt::format("error {}\n", response.status), "text/plain");
  });
  server.Get("/", [this](const httplib::Request&, httplib::Response& response) {
    response.set_content(page, "text/html; charset=utf-8");
  });
}

void ViewerServer::Impl::add_routes() {
  server.Get("/map.bin", [this](const httplib::Request&, httplib::Response& response) {
    response.set_content(map_bytes, "application/octet-stream");
  });
  server.Get(R"(/scan/(\d+))",
             [this](const httplib::Request& request, httplib::Response& response) { send_scan(request, response); });
}

void ViewerServer::Impl::add_live_routes() {
  server.Get("/live.json", [this](const httplib::Request& request, httplib::Response& response) {
    const auto revision = number_parameter(request, "revision");
    const auto frames = number_parameter(request, "frames");
    if (!revision) return bad_parameter(response, "revision");
    if (!frames) return bad_parameter(response, "frames");
    response.set_content(live->state_json(*revision, static_cast<std::size_t>(*frames)), "application/json");
  });
  server.Get("/live/map", [this](const httplib::Request& request, httplib::Response& response) {
    const auto from = number_parameter(request, "from");
    if (!from) return bad_parameter(response, "from");
    response.set_content(live->map_chunks(static_cast<std::size_t>(*from)), "application/octet-stream");
  });
  server.Get("/live/scan", [this](const httplib::Request&, httplib::Response& response) {
    response.set_content(live->latest_scan(), "application/octet-stream");
  });
  server.Get("/live/background", [this](const httplib::Request&, httplib::Response& response) {
    response.set_content(live->background(), "application/octet-stream");
  });
}

void ViewerServer::Impl::send_scan(const httplib::Request& request, httplib::Response& response) const {
  const std::string number = request.matches[1].str();
  std::size_t frame = 0;
  const bool parsed = number.size() <= 9 && std::from_chars(number.data(), number.data() + number.size(), frame).ec == std::errc{};
  try {
    if (!parsed) throw std::out_of_range("no such frame");
    response.set_content(encode_scan(load_viewer_scan(scene, frame, options.points_per_scan)),
                         "application/octet-stream");
  } catch (const std::exception& e) {  // a frame out of range, an unreadable scan
    // The details (file names, absolute paths) stay in the server's log.
    spdlog::warn("scan {}: {}", plain_error_text(number, 40), e.what());
    response.status = 404;
    response.set_content(fmt::format("scan {}: not available (see the server's log)\n", plain_error_text(number, 40)),
                         "text/plain");
  }
}

void ViewerServer::Impl::configure() {
  add_common_routes();
  // httplib's default adds SO_REUSEPORT, with which a second server binds a
  // port in use and the kernel splits the connections between the two:
  // SO_REUSEADDR alone (a port in TIME_WAIT is taken again, one in use is refused).
  server.set_socket_options([](socket_t socket) {
    const int yes = 1;
    setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  server.new_task_queue = [] { return new httplib::ThreadPool(kWorkerThreads); };
  server.set_keep_alive_timeout(kKeepAliveSeconds);
  server.set_read_timeout(kReadSeconds, 0);
  server.set_write_timeout(kWriteSeconds, 0);
  server.set_payload_max_length(kMaxRequestBodyBytes);
}

ViewerServer::ViewerServer(ViewerScene scene, const ViewerOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->page = viewer_page(scene, options, ViewerDataSource::kServer);
  impl_->map_bytes = encode_map(scene.map, map_quantization(scene.map));
  impl_->scene = std::move(scene);
  impl_->configure();
  impl_->add_routes();
}

ViewerServer::ViewerServer(std::shared_ptr<const LiveView> live) : impl_(std::make_unique<Impl>()) {
  if (!live) throw std::invalid_argument("ViewerServer: no live view");
  impl_->page = live_viewer_page(kLivePollMs);
  impl_->live = std::move(live);
  impl_->configure();
  impl_->add_live_routes();
}

ViewerServer::~ViewerServer() { stop(); }

int ViewerServer::start(const std::string& host, int port) {
  if (impl_->listener.joinable()) throw std::logic_error("ViewerServer::start: already started");
  const int bound =
      port == 0 ? impl_->server.bind_to_any_port(host) : (impl_->server.bind_to_port(host, port) ? port : -1);
  if (bound <= 0) throw InputError(fmt::format("{}:{}", host, port), "cannot listen there (port in use?)");
  impl_->port = bound;
  impl_->listener = std::thread([impl = impl_.get()] {
    impl->server.listen_after_bind();
    impl->listen_returned = true;
  });
  // httplib's stop() does nothing before its listening loop runs: wait for it,
  // so that stop() always ends what start() began.
  while (!impl_->server.is_running() && !impl_->listen_returned)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return bound;
}

void ViewerServer::stop() {
  if (!impl_->listener.joinable()) return;
  impl_->server.stop();
  impl_->listener.join();
}

bool ViewerServer::running() const { return impl_->server.is_running(); }

std::size_t ViewerServer::page_bytes() const { return impl_->page.size(); }

}  // namespace saloam
