#include "saloam/viewer/viewer_page.hpp"

#include <fstream>
#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/viewer/point_encoding.hpp"
#include "saloam/viewer/viewer_assets.hpp"

namespace saloam {

namespace {

using nlohmann::json;

json class_table() {
  json classes = json::array();
  for (const SemanticClass& c : semantic_kitti_classes()) {
    classes.push_back({{"id", c.id}, {"name", c.name}, {"color", {c.color.r, c.color.g, c.color.b}}});
  }
  classes.push_back({{"id", -1}, {"name", "unknown"}, {"color", {128, 128, 128}}});
  return classes;
}

/// [class index, first point, point count] of each class run of the sorted map.
json class_ranges(const LabelledCloud& map) {
  json ranges = json::array();
  for (std::size_t begin = 0; begin < map.size();) {
    const std::uint8_t index = class_index(map.label[begin]);
    std::size_t end = begin;
    while (end < map.size() && class_index(map.label[end]) == index) ++end;
    ranges.push_back({index, begin, end - begin});
    begin = end;
  }
  return ranges;
}

json map_json(const ViewerScene& scene, ViewerDataSource source) {
  const MapQuantization q = map_quantization(scene.map);
  json map{{"count", scene.map.size()},
           {"total", scene.map_points_total},
           {"origin", {q.origin.x(), q.origin.y(), q.origin.z()}},
           {"scale", q.scale},
           {"ranges", class_ranges(scene.map)}};
  if (source == ViewerDataSource::kEmbedded) map["data"] = base64(encode_map(scene.map, q));
  return map;
}

std::string positions_base64(const std::vector<Pose>& poses) {
  std::vector<float> xyz;
  xyz.reserve(poses.size() * 3);
  for (const Pose& p : poses) {
    for (int a = 0; a < 3; ++a) xyz.push_back(static_cast<float>(p.translation()[a]));
  }
  return base64(encode_floats(xyz));
}

// Session colours, apart from the loop edges' cyan and magenta and the slider's yellow.
constexpr const char* kSessionColors[] = {"#3b9cff", "#ff9800", "#8bc34a", "#7c4dff", "#f44336", "#00bfa5", "#a1887f"};

/// A saved map: one trajectory per session (its keyframes), in its colour.
json session_trajectories_json(const ViewerScene& scene) {
  json list = json::array();
  for (std::size_t i = 0; i < scene.sessions.size(); ++i) {
    const ViewerSession& session = scene.sessions[i];
    std::vector<Pose> poses;
    for (const std::size_t k : session.frames) poses.push_back(scene.loop_closed[k]);
    std::string name = fmt::format("session {}", i);
    if (!session.name.empty()) name += ": " + std::filesystem::path(session.name).filename().string();
    if (!session.linked) name += " (not linked: own frame)";
    list.push_back({{"name", name},
                    {"color", kSessionColors[i % std::size(kSessionColors)]},
                    {"count", fmt::format("{} keyframes", session.frames.size())},
                    {"session", i},
                    {"positions", positions_base64(poses)}});
  }
  return list;
}

json trajectories_json(const ViewerScene& scene) {
  if (!scene.sessions.empty()) return session_trajectories_json(scene);
  json list = json::array();
  const auto add = [&](const char* name, const char* color, const std::vector<Pose>& poses) {
    if (!poses.empty()) list.push_back({{"name", name}, {"color", color}, {"positions", positions_base64(poses)}});
  };
  add("ground truth", "#9a9a9a", scene.ground_truth);
  add("odometry", "#e8412f", scene.odometry);
  add("loop closed", "#3b9cff", scene.loop_closed);
  return list;
}

json scans_json(const ViewerScene& scene, const ViewerOptions& options, ViewerDataSource source,
                ViewerPageStats& stats) {
  json scans{{"scale", kScanScale}, {"source", "none"}, {"frames", json::array()}, {"data", json::array()}};
  if (!scene.scan_of) return scans;
  if (source == ViewerDataSource::kServer) {
    scans["source"] = "server";
    return scans;
  }
  scans["source"] = "embedded";
  for (const std::size_t frame : embedded_scan_frames(scene, options)) {
    const std::string bytes = encode_scan(load_viewer_scan(scene, frame, options.points_per_scan));
    scans["frames"].push_back(frame);
    scans["data"].push_back(base64(bytes));
    ++stats.scans;
    stats.scan_points += bytes.size() / 7;
  }
  return scans;
}

json page_data(const ViewerScene& scene, const ViewerOptions& options, ViewerDataSource source,
               ViewerPageStats& stats) {
  json loops = json::array(), cross_loops = json::array();
  for (const auto& [query, match] : scene.loops) loops.push_back({query, match});
  for (const auto& [query, match] : scene.cross_session_loops) cross_loops.push_back({query, match});
  return json{{"title", scene.run_dir.filename().empty() ? scene.run_dir.parent_path().filename().string()
                                                         : scene.run_dir.filename().string()},
              {"source", source == ViewerDataSource::kEmbedded ? "embedded" : "server"},
              {"kind", scene.sessions.empty() ? "run" : "map"},
              {"sessions", scene.sessions.size()},
              {"classes", class_table()},
              {"map", map_json(scene, source)},
              {"trajectories", trajectories_json(scene)},
              {"frames", scene.loop_closed.size()},
              {"first_frame", scene.first_frame},
              {"poses", poses_base64(scene.loop_closed)},
              {"loops", loops},
              {"loops_verified", scene.loops_verified},
              {"cross_loops", cross_loops},
              {"scans", scans_json(scene, options, source, stats)}};
}

/// JSON that is safe inside a <script> element ("</" would end it).
std::string script_safe(std::string text) {
  for (std::size_t at = text.find("</"); at != std::string::npos; at = text.find("</", at + 3))
    text.replace(at, 2, "<\\/");
  return text;
}

void replace_once(std::string& page, std::string_view placeholder, std::string_view text) {
  const std::size_t at = page.find(placeholder);
  if (at == std::string::npos) throw std::logic_error(fmt::format("the page template has no {}", placeholder));
  page.replace(at, placeholder.size(), text);
}

}  // namespace

bool viewer_has_three_js() { return !viewer_assets::kThreeJs.empty() && !viewer_assets::kOrbitControlsJs.empty(); }

namespace {

void require_three_js() {
  if (viewer_has_three_js()) return;
  throw InputError("/usr/share/javascript/three/three.min.js",
                   "three.js was not found when saloam was built: install the Debian package libjs-three "
                   "(scripts/install_deps.sh), then reconfigure and rebuild saloam");
}

/// A page template with three.js and `data` in place of its placeholders.
std::string fill_page(std::string_view page_template, const json& data) {
  std::string page(page_template);
  // Last placeholder first: every search finds its placeholder before any inserted text.
  replace_once(page, "/*SALOAM_DATA*/", script_safe(data.dump(-1, ' ', false, json::error_handler_t::replace)));
  replace_once(page, "/*SALOAM_ORBIT_CONTROLS_JS*/", viewer_assets::kOrbitControlsJs);
  replace_once(page, "/*SALOAM_THREE_JS*/", viewer_assets::kThreeJs);
  replace_once(page, "/*SALOAM_COMMON_JS*/", viewer_assets::kCommonJs);
  replace_once(page, "/*SALOAM_COMMON_CSS*/", viewer_assets::kCommonCss);
  return page;
}

}  // namespace

std::string viewer_page(const ViewerScene& scene, const ViewerOptions& options, ViewerDataSource source,
                        ViewerPageStats* stats) {
  require_three_js();
  ViewerPageStats local;
  ViewerPageStats& s = stats ? *stats : local;
  s = ViewerPageStats{};
  const std::string page = fill_page(viewer_assets::kPageTemplate, page_data(scene, options, source, s));
  s.bytes = page.size();
  s.map_points = scene.map.size();
  s.map_points_total = scene.map_points_total;
  s.frames = scene.loop_closed.size();
  s.loops = scene.loops.size();
  s.cross_session_loops = scene.cross_session_loops.size();
  s.sessions = scene.sessions.size();
  s.ground_truth = !scene.ground_truth.empty();
  return page;
}

std::string live_viewer_page(int poll_ms) {
  require_three_js();
  return fill_page(viewer_assets::kLivePageTemplate,
                   json{{"classes", class_table()}, {"scan_scale", kScanScale}, {"poll_ms", poll_ms}});
}

namespace {

// The page replaces only an earlier page: never a pose file, a map or a scan
// given by mistake as --out.
void check_replaceable(const std::filesystem::path& page) {
  if (!path_taken(page)) return;
  std::error_code error;
  if (std::filesystem::is_regular_file(page, error)) {
    std::ifstream in(page, std::ios::binary);
    std::string start(15, '\0');
    in.read(start.data(), static_cast<std::streamsize>(start.size()));
    if (in && start == "<!DOCTYPE html>") return;
  }
  throw InputError(page, "exists and is not a viewer page: the page never replaces another file; choose another --out");
}

}  // namespace

std::filesystem::path default_viewer_page(const std::filesystem::path& folder) {
  if (!is_map_folder(folder)) return folder / "view.html";
  std::filesystem::path map = folder.lexically_normal();
  if (map.filename().empty()) map = map.parent_path();  // "MAP/"
  if (map.filename().empty() || map.filename() == "." || map.filename() == "..") {
    map = std::filesystem::absolute(map).lexically_normal();
    if (map.filename().empty()) map = map.parent_path();
  }
  return map.parent_path() / (map.filename().string() + ".view.html");
}

ViewerPageStats write_viewer_page(const std::filesystem::path& run_dir, const std::filesystem::path& page,
                                  const ViewerOptions& options) {
  check_replaceable(page);
  const ViewerScene scene = load_viewer_scene(run_dir, options);
  ViewerPageStats stats;
  const std::string html = viewer_page(scene, options, ViewerDataSource::kEmbedded, &stats);
  stats.saved_map = scene.saved_map;
  write_file_atomically(page, html);
  return stats;
}

}  // namespace saloam
