#include "saloam/viewer/viewer_server.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"
#include "saloam/viewer/point_encoding.hpp"
#include "saloam/viewer/viewer_page.hpp"

// After Eigen: httplib.h includes <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

namespace saloam {

struct ViewerServer::Impl {
  ViewerScene scene;
  ViewerOptions options;
  std::string page;
  std::string map_bytes;
  httplib::Server server;

  void add_routes();
  void send_scan(const httplib::Request& request, httplib::Response& response) const;
};

void ViewerServer::Impl::add_routes() {
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
  try {
    const std::size_t frame = std::stoul(request.matches[1].str());
    response.set_content(encode_scan(load_viewer_scan(scene, frame, options.points_per_scan)),
                         "application/octet-stream");
  } catch (const std::exception& e) {  // a frame out of range, an unreadable scan
    response.status = 404;
    response.set_content(e.what(), "text/plain");
  }
}

ViewerServer::ViewerServer(ViewerScene scene, const ViewerOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->page = viewer_page(scene, options, ViewerDataSource::kServer);
  impl_->map_bytes = encode_map(scene.map, map_quantization(scene.map));
  impl_->scene = std::move(scene);
  impl_->add_routes();
}

ViewerServer::~ViewerServer() { stop(); }

int ViewerServer::bind(const std::string& host, int port) {
  const int bound =
      port == 0 ? impl_->server.bind_to_any_port(host) : (impl_->server.bind_to_port(host, port) ? port : -1);
  if (bound <= 0) throw InputError(fmt::format("{}:{}", host, port), "cannot listen there (port in use?)");
  return bound;
}

void ViewerServer::listen() { impl_->server.listen_after_bind(); }

void ViewerServer::stop() { impl_->server.stop(); }

bool ViewerServer::running() const { return impl_->server.is_running(); }

std::size_t ViewerServer::page_bytes() const { return impl_->page.size(); }

}  // namespace saloam
