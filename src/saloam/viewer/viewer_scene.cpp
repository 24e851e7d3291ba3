#include "saloam/viewer/viewer_scene.hpp"

#include <algorithm>
#include <numeric>
#include <random>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/ply.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/maps/map_format.hpp"

namespace saloam {

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMaxSummaryBytes = std::size_t{64} << 20;
constexpr std::size_t kMaxLoopFileBytes = std::size_t{256} << 20;

fs::path required_file(const fs::path& run_dir, const std::string& name, const std::string& what) {
  const fs::path file = run_dir / name;
  if (!fs::is_regular_file(file)) {
    throw InputError(file,
                     fmt::format("not found: {} (is {} the output folder of `saloam slam`?)", what, run_dir.string()));
  }
  return file;
}

/// CSV fields of one line; double quotes group a field with commas.
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (const char c : line) {
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

std::size_t column_of(const std::vector<std::string>& header, const std::string& name, const fs::path& file) {
  const auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end()) throw InputError(file, fmt::format("no '{}' column", name));
  return static_cast<std::size_t>(it - header.begin());
}

std::size_t parse_index(const std::string& text, const fs::path& file, std::size_t line) {
  try {
    std::size_t used = 0;
    const unsigned long value = std::stoul(text, &used);
    if (used == text.size()) return value;
  } catch (const std::exception&) {
  }
  throw InputError(file, fmt::format("line {}: '{}' is not a frame index", line, text));
}

struct RunSummary {
  std::optional<fs::path> sequence;
  std::size_t first_frame = 0;
  std::optional<fs::path> saved_map;
};

// The map folder that summary.json's "saved_map" names (slam --save-map), if any.
std::optional<fs::path> saved_map_of(const nlohmann::json& summary, const fs::path& file) {
  const auto saved = summary.find("saved_map");
  if (saved == summary.end()) return std::nullopt;
  if (!saved->is_object() || !saved->contains("folder") || !saved->at("folder").is_string()) {
    throw InputError(file, "\"saved_map\" is not an object with a \"folder\" path");
  }
  return fs::path(saved->at("folder").get<std::string>());
}

RunSummary read_run_summary(const fs::path& run_dir) {
  RunSummary summary;
  const fs::path file = run_dir / "summary.json";
  if (!path_taken(file)) return summary;
  const auto json = nlohmann::json::parse(read_file(file, kMaxSummaryBytes, "run summary"), nullptr, false);
  const auto sequence = json.is_object() ? json.find("sequence") : json.end();
  const auto first = json.is_object() ? json.find("first_frame") : json.end();
  if (!json.is_object() || (sequence != json.end() && !sequence->is_string()) ||
      (first != json.end() && !first->is_number_unsigned())) {
    throw InputError(file, "not a summary of `saloam slam` (a JSON object with \"sequence\" and \"first_frame\")");
  }
  if (sequence != json.end()) summary.sequence = fs::path(sequence->get<std::string>());
  // A path that is not UTF-8 is recorded exactly in hex beside its readable text.
  if (const auto hex = json.find("sequence_hex"); hex != json.end() && hex->is_string()) {
    const auto bytes = from_hex(hex->get<std::string>());
    if (!bytes) throw InputError(file, "\"sequence_hex\" is not a hexadecimal path");
    summary.sequence = fs::path(*bytes);
  }
  if (first != json.end()) summary.first_frame = first->get<std::size_t>();
  summary.saved_map = saved_map_of(json, file);
  return summary;
}

std::optional<fs::path> sequence_folder(const RunSummary& summary, const ViewerOptions& options) {
  if (options.sequence) {
    if (!fs::is_directory(*options.sequence)) throw InputError(*options.sequence, "sequence folder not found");
    return options.sequence;
  }
  if (summary.sequence && fs::is_directory(*summary.sequence / "velodyne")) return summary.sequence;
  if (summary.sequence && fs::is_directory(*summary.sequence)) {
    spdlog::warn("{}: the run read another layout than a SemanticKITTI folder; no ground truth and no scans (give "
                 "--sequence)",
                 summary.sequence->string());
    return std::nullopt;
  }
  if (summary.sequence) {
    spdlog::warn("{}: the run's sequence folder is gone; no ground truth and no scans (give --sequence)",
                 summary.sequence->string());
  }
  return std::nullopt;
}

std::vector<Pose> read_tum_poses(const fs::path& file) { return read_tum_trajectory(file).poses; }

/// Ground truth of frames [first, first + count) in the LiDAR frame, world =
/// the first of them (as the estimates); empty without poses.txt.
std::vector<Pose> ground_truth_lidar(const SequenceReader& reader, std::size_t first, std::size_t count) {
  if (!reader.has_poses() || count == 0) return {};
  const auto& camera = reader.camera_poses();
  if (first + count > camera.size()) {
    throw InputError(reader.root() / "poses.txt", fmt::format("{} poses, but the run processed frames {}..{}",
                                                              camera.size(), first, first + count - 1));
  }
  const Pose tr = reader.has_calib() ? reader.velo_to_cam() : Pose::Identity();
  const Pose rebase = camera[first].inverse();
  std::vector<Pose> lidar;
  lidar.reserve(count);
  for (std::size_t i = first; i < first + count; ++i)
    lidar.push_back(orthonormalized(tr.inverse() * rebase * camera[i] * tr));
  return lidar;
}

void check_loops(const std::vector<std::pair<std::size_t, std::size_t>>& loops, std::size_t frames,
                 const fs::path& file) {
  for (const auto& [query, match] : loops) {
    if (query >= frames || match >= frames) {
      throw InputError(file, fmt::format("loop {}-{} beyond the {} poses of poses_tum.txt", query, match, frames));
    }
  }
}

/// The loop-closed and odometry trajectories and the accepted loops of the run.
void read_trajectories_and_loops(ViewerScene& scene) {
  const fs::path& dir = scene.run_dir;
  scene.loop_closed = read_tum_poses(required_file(dir, "poses_tum.txt", "the loop-closed trajectory"));
  if (scene.loop_closed.empty()) throw InputError(dir / "poses_tum.txt", "no poses");
  if (fs::is_regular_file(dir / "poses_odometry_tum.txt"))
    scene.odometry = read_tum_poses(dir / "poses_odometry_tum.txt");
  if (fs::is_regular_file(dir / "loops.csv")) {
    scene.loops = read_accepted_loops(dir / "loops.csv", &scene.loops_verified);
    check_loops(scene.loops, scene.loop_closed.size(), dir / "loops.csv");
  }
}

/// The sequence the run processed, when known, with its ground truth.
void attach_sequence(ViewerScene& scene, const RunSummary& summary, const ViewerOptions& options) {
  scene.first_frame = summary.first_frame;
  if (options.ground_truth || options.scans) {  // frames from memory
    if (options.ground_truth && options.ground_truth->size() != scene.loop_closed.size()) {
      throw InputError(scene.run_dir, fmt::format("{} ground-truth poses given for a run of {} frames",
                                                  options.ground_truth->size(), scene.loop_closed.size()));
    }
    if (options.ground_truth) scene.ground_truth = *options.ground_truth;
    scene.scan_of = options.scans;
    return;
  }
  const auto folder = sequence_folder(summary, options);
  if (!folder) return;
  scene.sequence = std::make_shared<const SequenceReader>(*folder);
  const std::size_t frames = scene.loop_closed.size();
  if (scene.first_frame + frames > scene.sequence->size()) {
    throw InputError(*folder, fmt::format("{} scans, but the run has poses of frames {}..{}: another sequence?",
                                          scene.sequence->size(), scene.first_frame, scene.first_frame + frames - 1));
  }
  scene.ground_truth = ground_truth_lidar(*scene.sequence, scene.first_frame, frames);
  scene.scan_of = [sequence = scene.sequence, first = scene.first_frame](std::size_t frame) {
    return sequence->load_scan(first + frame);
  };
}

/// A keyframe's features as a labelled cloud (SemanticKITTI ids of their
/// training classes), moved by `pose` (T_map<-sensor; identity: sensor frame).
LabelledCloud features_cloud(const StoredFeatures& features, const Pose& pose) {
  LabelledCloud cloud;
  cloud.has_labels = true;
  cloud.reserve(features.edge_points.size() + features.planar_points.size());
  const Eigen::Isometry3f to_map = pose.cast<float>();
  const auto add = [&](const std::vector<Eigen::Vector3f>& points, const std::vector<ClassIndex>& classes) {
    for (std::size_t i = 0; i < points.size(); ++i)
      cloud.push_back(to_map * points[i], 0.0F, from_learning_class(classes[i]));
  };
  add(features.edge_points, features.edge_classes);
  add(features.planar_points, features.planar_classes);
  return cloud;
}

}  // namespace

bool is_map_folder(const fs::path& folder) {
  std::error_code error;
  return fs::is_regular_file(folder / "map.json", error);
}

ViewerScene load_map_viewer_scene(const fs::path& map_folder, const ViewerOptions& options) {
  if (options.sequence || options.ground_truth || options.scans) {
    throw InputError(map_folder, "a saved map is viewed without a sequence: its keyframes' features are the scans "
                                 "at the slider (drop --sequence)");
  }
  const SavedMap saved = read_map(map_folder);
  ViewerScene scene;
  scene.run_dir = map_folder;
  for (const MapSession& s : map_sessions(saved)) scene.sessions.push_back({s.source, {}, s.linked});
  for (std::size_t k = 0; k < saved.keyframes.size(); ++k) {
    const MapKeyframe& kf = saved.keyframes[k];
    if (kf.session >= scene.sessions.size()) {
      throw InputError(map_folder / "keyframes.bin",
                       fmt::format("keyframe {}: session {} of {}", k, kf.session, scene.sessions.size()));
    }
    scene.loop_closed.push_back(kf.pose);
    scene.sessions[kf.session].frames.push_back(k);
  }
  for (const PoseGraphEdge& e : saved.edges) {
    if (e.kind != EdgeKind::kLoop) continue;
    const bool across = saved.keyframes[e.from].session != saved.keyframes[e.to].session;
    (across ? scene.cross_session_loops : scene.loops).emplace_back(e.from, e.to);
  }
  scene.loops_verified = scene.loops.size();  // a map keeps only accepted loops
  // The map: each keyframe's share of the budget, one keyframe in memory at a time.
  const std::size_t keyframes = saved.keyframes.size();
  const std::size_t share = keyframes == 0 ? 0 : (options.max_map_points + keyframes - 1) / keyframes;
  LabelledCloud map;
  map.has_labels = true;
  for (std::size_t k = 0; k < keyframes; ++k) {
    const LabelledCloud cloud = features_cloud(read_map_features(saved, k), saved.keyframes[k].pose);
    scene.map_points_total += cloud.size();
    const LabelledCloud part = decimate_cloud(cloud, share);
    for (std::size_t i = 0; i < part.size(); ++i) map.push_back_from(part, i);
  }
  scene.map = decimate_cloud(map, options.max_map_points);
  auto digests = std::make_shared<SavedMap>();
  digests->folder = saved.folder;
  digests->manifest = saved.manifest;
  digests->feature_digests = saved.feature_digests;
  scene.scan_of = [digests](std::size_t frame) { return features_cloud(read_map_features(*digests, frame), Pose::Identity()); };
  return scene;
}

std::vector<std::pair<std::size_t, std::size_t>> read_accepted_loops(const fs::path& file, std::size_t* verified) {
  std::istringstream in(read_file(file, kMaxLoopFileBytes, "loop file"));
  std::string line;
  if (!std::getline(in, line)) throw InputError(file, "empty loop file (no header)");
  const auto header = csv_fields(line);
  const std::size_t query = column_of(header, "query_frame", file);
  const std::size_t match = column_of(header, "match_frame", file);
  const std::size_t accepted = column_of(header, "accepted", file);
  std::vector<std::pair<std::size_t, std::size_t>> loops;
  std::size_t rows = 0;
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    const auto fields = csv_fields(line);
    if (fields.size() < header.size())
      throw InputError(file, fmt::format("line {}: {} fields, {} expected", number, fields.size(), header.size()));
    ++rows;
    if (fields[accepted] == "1")
      loops.emplace_back(parse_index(fields[query], file, number), parse_index(fields[match], file, number));
  }
  if (verified) *verified = rows;
  return loops;
}

LabelledCloud decimate_cloud(const LabelledCloud& cloud, std::size_t budget) {
  std::vector<std::size_t> order(cloud.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  if (order.size() > budget) {
    std::mt19937_64 rng(1);  // deterministic: the same page for the same run
    std::shuffle(order.begin(), order.end(), rng);
    order.resize(budget);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return cloud.label[a] < cloud.label[b]; });
  LabelledCloud out;
  out.has_labels = cloud.has_labels;
  out.reserve(order.size());
  for (const std::size_t i : order) out.push_back_from(cloud, i);
  return out;
}

ViewerScene load_viewer_scene(const fs::path& run_dir, const ViewerOptions& options) {
  if (!fs::is_directory(run_dir)) throw InputError(run_dir, "run folder not found (the --out folder of `saloam slam`)");
  if (is_map_folder(run_dir)) return load_map_viewer_scene(run_dir, options);
  ViewerScene scene;
  scene.run_dir = run_dir;
  const fs::path map_file = required_file(run_dir, "map.ply", "the global map (run `saloam slam` without --no-map)");
  read_trajectories_and_loops(scene);
  const RunSummary summary = read_run_summary(run_dir);
  attach_sequence(scene, summary, options);
  scene.saved_map = summary.saved_map;
  const LabelledCloud map = read_ply(map_file);
  scene.map_points_total = map.size();
  scene.map = decimate_cloud(map, options.max_map_points);
  return scene;
}

LabelledCloud load_viewer_scan(const ViewerScene& scene, std::size_t frame, std::size_t max_points) {
  if (!scene.scan_of) throw InputError(scene.run_dir, "no sequence folder known for the scans (give --sequence)");
  if (frame >= scene.loop_closed.size()) {
    throw InputError(scene.run_dir,
                     fmt::format("frame {} out of range (the run has {} frames)", frame, scene.loop_closed.size()));
  }
  return decimate_cloud(scene.scan_of(frame), max_points);
}

std::vector<std::size_t> embedded_scan_frames(const ViewerScene& scene, const ViewerOptions& options) {
  const std::size_t frames = scene.loop_closed.size();
  if (!scene.scan_of || options.points_per_scan == 0 || frames == 0) return {};
  const std::size_t count = std::min(frames, options.max_scan_points / options.points_per_scan);
  if (count == 0) return {};
  const std::size_t step = (frames + count - 1) / count;
  std::vector<std::size_t> result;
  for (std::size_t f = 0; f < frames; f += step) result.push_back(f);
  return result;
}

}  // namespace saloam
