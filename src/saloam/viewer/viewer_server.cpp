#include "saloam/viewer/viewer_server.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <stdexcept>
#include <string_view>

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
}  // namespace

struct ViewerServer::Impl {
  ViewerScene scene;
  ViewerOptions options;
  std::string page;
  std::string map_bytes;
  httplib::Server server;
  int port = 0;  ///< bound port, for the Host check

  void add_routes();
  void send_scan(const httplib::Request& request, httplib::Response& response) const;
};

bool viewer_host_allowed(std::string_view host, int port) {
  const std::string suffix = fmt::format(":{}", port);
  if (host.size() <= suffix.size() || host.substr(host.size() - suffix.size()) != suffix) return false;
  std::string name(host.substr(0, host.size() - suffix.size()));
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  return name == "127.0.0.1" || name == "localhost" || name == "[::1]";
}

void ViewerServer::Impl::add_routes() {
  // DNS rebinding: a page of another site whose name now resolves to
  // 127.0.0.1 sends its own name as Host. Only the loopback names pass.
  server.set_pre_routing_handler([this](const httplib::Request& request, httplib::Response& response) {
    if (viewer_host_allowed(request.get_header_value("Host"), port)) return httplib::Server::HandlerResponse::Unhandled;
    response.status = 403;
    response.set_content("forbidden: the viewer answers only to 127.0.0.1, localhost or [::1] with its port\n",
                         "text/plain");
    return httplib::Server::HandlerResponse::Handled;
  });
  server.set_error_handler([](const httplib::Request&, httplib::Response& response) {
    if (response.body.empty()) response.set_content(fmt::format("error {}\n", response.status), "text/plain");
  });
  server.Get("/", [this](const httplib::Request&, httplib::Response& response) {
    response.set_content(page, "text/html; charset=utf-8");
  });
  server.Get("/map.bin", [this](const httplib::Request&, httplib::Response& response) {
    response.set_content(map_bytes, "application/octet-stream");
  });
  server.Get(R"(/scan/(\d+))",
             [this](const httplib::Request& request, httplib::Response& response) { send_scan(request, response); });
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

ViewerServer::ViewerServer(ViewerScene scene, const ViewerOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->page = viewer_page(scene, options, ViewerDataSource::kServer);
  impl_->map_bytes = encode_map(scene.map, map_quantization(scene.map));
  impl_->scene = std::move(scene);
  impl_->add_routes();
  impl_->server.new_task_queue = [] { return new httplib::ThreadPool(kWorkerThreads); };
  impl_->server.set_keep_alive_timeout(kKeepAliveSeconds);
  impl_->server.set_read_timeout(kReadSeconds, 0);
  impl_->server.set_write_timeout(kWriteSeconds, 0);
  impl_->server.set_payload_max_length(kMaxRequestBodyBytes);
}

ViewerServer::~ViewerServer() { stop(); }

int ViewerServer::bind(const std::string& host, int port) {
  const int bound =
      port == 0 ? impl_->server.bind_to_any_port(host) : (impl_->server.bind_to_port(host, port) ? port : -1);
  if (bound <= 0) throw InputError(fmt::format("{}:{}", host, port), "cannot listen there (port in use?)");
  impl_->port = bound;
  return bound;
}

void ViewerServer::listen() { impl_->server.listen_after_bind(); }

void ViewerServer::stop() { impl_->server.stop(); }

bool ViewerServer::running() const { return impl_->server.is_running(); }

std::size_t ViewerServer::page_bytes() const { return impl_->page.size(); }

}  // namespace saloam
