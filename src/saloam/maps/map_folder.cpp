// A saved map's folder (docs/map_format.md): written whole into a temporary
// folder beside it and put in place in one atomic step
// (core/folder_replace.hpp), read back table by table with every count and
// reference checked; the tables' bytes are map_format.cpp's.
#include <algorithm>
#include <array>
#include <fstream>
#include <span>
#include <cstring>
#include <random>
#include <utility>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/folder_replace.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/digest.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/maps/map_format.hpp"

namespace fs = std::filesystem;

namespace saloam {

fs::path map_features_path(const fs::path& folder, std::size_t keyframe) {
  return folder / "features" / fmt::format("{:06d}.bin", keyframe);
}

namespace {

constexpr std::size_t kMaxManifestBytes = std::size_t{1} << 20;
constexpr std::size_t kMaxTableBytes = std::size_t{16} << 30;

std::string_view as_text(const std::vector<std::byte>& bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

// The bytes of one of the map's files, checked against the digest the
// manifest holds for it (a map before version 3 has none).
std::string read_checked(const fs::path& folder, const MapManifest& manifest, const std::string& name,
                         std::size_t max_bytes) {
  const fs::path file = folder / name;
  std::string text = read_file(file, max_bytes, "map file");
  const auto it = manifest.digests.find(name);
  if (it != manifest.digests.end() && fnv1a64(text) != it->second) {
    throw InputError(file, fmt::format("its digest {} is not the {} map.json lists: the file was cut or changed "
                                       "after the map was saved",
                                       digest_text(fnv1a64(text)), digest_text(it->second)));
  }
  return text;
}

// The size a table file may have, from its header's record count, checked
// before the file is read (a map table once was read whole, up to 16 GiB,
// and copied before its header was looked at).
std::size_t checked_table_size(const fs::path& file, MapTable table, const SaloamConfig& config) {
  std::error_code error;
  if (!fs::is_regular_file(file, error)) return kMaxTableBytes;  // read_file names what it is
  const std::uintmax_t size = fs::file_size(file, error);
  if (error) return kMaxTableBytes;
  std::array<std::byte, kMapTableHeadBytes> head{};
  std::ifstream in(file, std::ios::binary);
  in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  std::uint64_t most = kMaxTableBytes;
  try {
    most = std::min<std::uint64_t>(
        most, map_table_max_bytes(std::span<const std::byte>(head.data(), static_cast<std::size_t>(in.gcount())),
                                  table, config, file));
  } catch (const InputError&) {
    return kMaxTableBytes;  // a bad header: the digest and the parser name the problem
  }
  if (size > most) {
    throw InputError(file, fmt::format("{} bytes, more than the {} its header's records can take: not read", size,
                                       most));
  }
  return static_cast<std::size_t>(most);
}

// A table's bytes, as read (no copy), checked against its digest.
std::string read_table(const fs::path& folder, const MapManifest& manifest, const std::string& name, MapTable table,
                       const SaloamConfig& config) {
  return read_checked(folder, manifest, name, checked_table_size(folder / name, table, config));
}

std::span<const std::byte> bytes_of(const std::string& text) { return std::as_bytes(std::span<const char>(text)); }

void collect_keys(const YAML::Node& node, const std::string& prefix, std::vector<std::string>& keys) {
  if (!node.IsMap()) {
    keys.push_back(prefix);
    return;
  }
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    collect_keys(entry.second, prefix.empty() ? key : prefix + "." + key, keys);
  }
}

bool holds_key(const YAML::Node& node, std::string_view key) {
  if (!node.IsMap()) return false;
  const std::size_t dot = key.find('.');
  const YAML::Node next = node[std::string(key.substr(0, dot))];  // a const node: nothing is inserted
  if (!next.IsDefined()) return false;
  return dot == std::string_view::npos || holds_key(next, key.substr(dot + 1));
}

// The keys (dotted, e.g. "odometry.alpha") that config_to_yaml(`config`)
// writes and `yaml_text` lacks.
std::vector<std::string> missing_config_keys(std::string_view yaml_text, const SaloamConfig& config) {
  std::vector<std::string> expected, missing;
  collect_keys(YAML::Load(config_to_yaml(config)), "", expected);
  YAML::Node given;
  try {
    given = YAML::Load(std::string(yaml_text));
  } catch (const YAML::Exception&) {
    return expected;
  }
  for (const std::string& key : expected) {
    if (!holds_key(given, key)) missing.push_back(key);
  }
  return missing;
}

// A fresh map identity: 128 random bits as 32 hexadecimal digits.
std::string new_map_id() {
  std::random_device random;
  std::string id;
  for (int i = 0; i < 4; ++i) id += fmt::format("{:08x}", static_cast<std::uint32_t>(random()));
  return id;
}

bool is_saloam_map(const fs::path& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return false;
  try {
    parse_map_manifest(read_file(folder / "map.json", kMaxManifestBytes, "map manifest"), folder / "map.json");
    return true;
  } catch (const InputError&) {
    return false;
  }
}

// The manifest's sessions with their keyframe counts from the keyframes (a
// map of one session without a list gets one from the manifest's source).
std::vector<MapSession> counted_sessions(const SavedMap& map) {
  std::vector<MapSession> sessions = map_sessions(map);
  for (MapSession& s : sessions) s.keyframes = 0;
  for (std::size_t k = 0; k < map.keyframes.size(); ++k) {
    const std::uint32_t s = map.keyframes[k].session;
    const bool in_order = s < sessions.size() && (k == 0 ? s == 0 : s == map.keyframes[k - 1].session ||
                                                                      s == map.keyframes[k - 1].session + 1);
    if (!in_order) throw InputError(map.folder, fmt::format("keyframe {}: session {} out of order", k, s));
    ++sessions[s].keyframes;
  }
  if (sessions.back().keyframes == 0) throw InputError(map.folder, "a session without keyframes");
  sessions.front().linked = true;
  return sessions;
}

// Each session of the manifest holds the keyframes marked with it.
void check_sessions(const SavedMap& map, const fs::path& keyframes_file) {
  std::vector<std::uint64_t> counts(map.manifest.sessions.size(), 0);
  for (const MapKeyframe& kf : map.keyframes) {
    if (kf.session >= counts.size()) {
      throw InputError(keyframes_file, fmt::format("session {}; map.json lists {}", kf.session, counts.size()));
    }
    ++counts[kf.session];
  }
  for (std::size_t s = 0; s < counts.size(); ++s) {
    if (counts[s] != map.manifest.sessions[s].keyframes) {
      throw InputError(keyframes_file, fmt::format("session {} has {} keyframes, map.json says {}", s, counts[s],
                                                   map.manifest.sessions[s].keyframes));
    }
  }
}

// How far a saved keyframe pose may sit from where its odometry edge puts it
// relative to the keyframe before: the pose graph spreads a loop's
// correction over the edges between, a few centimetres to decimetres per
// edge on real drives; an edge or a pose changed by an edit is metres to
// kilometres off.
constexpr double kMaxEdgeCorrection = 1.0;          // [m], plus the fraction below of the edge's length
constexpr double kMaxEdgeCorrectionFraction = 0.25;
constexpr double kMaxEdgeRotationCorrection = 0.2;  // [rad]
// An odometry edge is the odometry's motion between its keyframes' odometry
// poses, computed from the same stored doubles: equal but for rounding.
constexpr double kOdometryEdgeTolerance = 1e-3;          // [m]
constexpr double kOdometryEdgeRotationTolerance = 1e-5;  // [rad]

// The loop edges of a map, and those of them between two sessions (the
// manifest's loop_edges and cross_session_loops).
struct LoopCounts {
  std::uint64_t loops = 0, cross_session = 0;
};
LoopCounts loop_counts(const SavedMap& map) {
  LoopCounts counts;
  for (const PoseGraphEdge& e : map.edges) {
    if (e.kind != EdgeKind::kLoop) continue;
    ++counts.loops;
    counts.cross_session += map.keyframes[e.from].session != map.keyframes[e.to].session;
  }
  return counts;
}

// How far the motion `a` is from `b`: translation [m] and rotation [rad].
std::pair<double, double> motion_difference(const Pose& a, const Pose& b) {
  return {(a.translation() - b.translation()).norm(), rotation_angle(a.inverse() * b)};
}

// The edges agree with the keyframes and the manifest (issue #39: a map whose
// digests were fitted to an edit is still refused): odometry edges join
// consecutive keyframes of one session and measure the motion between their
// odometry poses; the optimised poses are within a loop correction of every
// odometry edge; the loop counts are the manifest's.
void check_graph(const SavedMap& map, const fs::path& edges_file) {
  for (std::size_t i = 0; i < map.edges.size(); ++i) {
    const PoseGraphEdge& e = map.edges[i];
    if (e.kind == EdgeKind::kLoop) continue;
    const MapKeyframe& from = map.keyframes[e.from];
    const MapKeyframe& to = map.keyframes[e.to];
    if (e.to != e.from + 1 || from.session != to.session) {
      throw InputError(edges_file, fmt::format("odometry edge {}: keyframes {} -> {} are not consecutive keyframes of "
                                               "one session",
                                               i, e.from, e.to));
    }
    const auto [offset, turn] = motion_difference(from.odometry_pose.inverse() * to.odometry_pose, e.measured);
    if (offset > kOdometryEdgeTolerance || turn > kOdometryEdgeRotationTolerance) {
      throw InputError(edges_file, fmt::format("odometry edge {}: measures {:.3f} m and {:.5f} rad away from the motion "
                                               "between the odometry poses of keyframes {} and {}",
                                               i, offset, turn, e.from, e.to));
    }
    const auto [correction, rotation] = motion_difference(from.pose.inverse() * to.pose, e.measured);
    const double allowed = kMaxEdgeCorrection + kMaxEdgeCorrectionFraction * e.measured.translation().norm();
    if (correction > allowed || rotation > kMaxEdgeRotationCorrection) {
      throw InputError(edges_file.parent_path() / "keyframes.bin",
                       fmt::format("keyframes {} and {}: their poses are {:.3f} m and {:.3f} rad from their odometry "
                                   "edge's {:.3f} m (at most {:.3f} m and {} rad: a loop's correction)",
                                   e.from, e.to, correction, rotation, e.measured.translation().norm(), allowed,
                                   kMaxEdgeRotationCorrection));
    }
  }
  const LoopCounts counts = loop_counts(map);
  if (counts.loops != map.manifest.loop_edges || counts.cross_session != map.manifest.cross_session_loops) {
    throw InputError(edges_file, fmt::format("{} loop edges ({} between sessions), map.json says {} ({})", counts.loops,
                                             counts.cross_session, map.manifest.loop_edges,
                                             map.manifest.cross_session_loops));
  }
}

// Removes a folder when it goes out of scope still armed.
struct RemoveOnFailure {
  const fs::path& path;
  bool armed = true;
  ~RemoveOnFailure() {
    std::error_code ignored;
    if (armed) fs::remove_all(path, ignored);
  }
};

// The manifest of `map` as written: its counts, detector and sessions.
MapManifest manifest_to_write(const SavedMap& map) {
  MapManifest manifest = map.manifest;
  manifest.version = kMapFormatVersion;
  manifest.keyframes = map.keyframes.size();
  manifest.edges = map.edges.size();
  const LoopCounts loops = loop_counts(map);
  manifest.loop_edges = loops.loops;
  manifest.detector = map.config.loop.detector;
  manifest.sessions = counted_sessions(map);
  manifest.cross_session_loops = loops.cross_session;
  return manifest;
}

// Every file of the map into `folder`, the manifest last: a folder without one is no map.
void write_map_tables(const fs::path& folder, const SavedMap& map,
                      const std::function<const StoredFeatures&(std::size_t)>& features) {
  create_folder(folder / "features");
  MapManifest manifest = manifest_to_write(map);
  manifest.id = new_map_id();
  const auto put = [&](const fs::path& file, std::string_view bytes) {
    write_file_atomically(file, bytes);
    folder_replace_step(file.filename().string());
    return fnv1a64(bytes);
  };
  manifest.digests["config.yaml"] = put(folder / "config.yaml", config_to_yaml(map.config));
  manifest.digests["keyframes.bin"] = put(folder / "keyframes.bin", as_text(encode_map_keyframes(map.keyframes)));
  manifest.digests["edges.bin"] = put(folder / "edges.bin", as_text(encode_map_edges(map.edges)));
  manifest.digests["places.bin"] = put(folder / "places.bin", as_text(encode_map_places(map.places)));
  std::vector<std::uint64_t> feature_digests(map.keyframes.size());
  for (std::size_t k = 0; k < map.keyframes.size(); ++k) {
    feature_digests[k] = put(map_features_path(folder, k), as_text(encode_map_features(features(k))));
  }
  manifest.digests["digests.bin"] = put(folder / "digests.bin", as_text(encode_map_digests(feature_digests)));
  write_file_atomically(folder / "map.json", encode_map_manifest(manifest));
  folder_replace_step("map.json");
}

// MAP/config.yaml into map.config (its digest checked; version 3 on, every
// key present), its detector the manifest's.
void read_map_config(const fs::path& folder, SavedMap& map) {
  const fs::path config_file = folder / "config.yaml";
  const std::string config_text = read_checked(folder, map.manifest, "config.yaml", kMaxConfigBytes);
  try {
    apply_config_yaml(map.config, config_text, config_file.string());
  } catch (const ConfigError& e) {
    throw InputError(config_file, e.what());
  }
  if (map.manifest.version >= 3) {  // written whole by saloam: a missing key is a cut file, never a default
    const std::vector<std::string> missing = missing_config_keys(config_text, map.config);
    if (!missing.empty()) {
      throw InputError(config_file, fmt::format("holds no {} ({} keys missing): a map's configuration holds every key "
                                                "(is the file cut?)",
                                                missing.front(), missing.size()));
    }
  }
  if (map.config.loop.detector != map.manifest.detector) {
    throw InputError(folder / "map.json", fmt::format("detector \"{}\", but config.yaml says loop.detector \"{}\"",
                                                      map.manifest.detector, map.config.loop.detector));
  }
}

// Every place descriptor holds the one of the map's detector.
void check_place_descriptors(const SavedMap& map, const fs::path& places_file) {
  const PlaceDetector detector = parse_place_detector(map.manifest.detector);
  for (std::size_t k = 0; k < map.places.size(); ++k) {
    const PlaceDescriptor& p = map.places[k];
    const bool ok = (!uses_scan_context(detector) || p.context.descriptor.size() > 0) &&
                    (!uses_ssc(detector) || !p.ssc.key_range.empty()) && (!uses_sgpr(detector) || p.graph.nodes.size() > 0 ||
                                                                          p.embedding.squaredNorm() > 0);
    if (!ok) {
      throw InputError(places_file, fmt::format("place {} lacks the descriptor of the map's detector {}", k, map.manifest.detector));
    }
  }
}

}  // namespace

void check_map_destination(const fs::path& folder) {
  if (path_taken(folder) && !is_saloam_map(folder)) {
    throw InputError(folder, "exists and is not a saloam map: it is left as it is (choose another --save-map)");
  }
}

void write_map(const fs::path& folder, const SavedMap& map,
               const std::function<const StoredFeatures&(std::size_t)>& features) {
  check_map_destination(folder);
  if (map.keyframes.empty()) throw InputError(folder, "no keyframe to save: the map would be empty");
  if (map.places.size() != map.keyframes.size()) throw InputError(folder, "one place descriptor per keyframe is needed");
  if (!folder.parent_path().empty()) create_folder(folder.parent_path());
  recover_folder(folder, is_saloam_map);
  const fs::path temporary = partial_folder_name(folder);
  RemoveOnFailure cleanup{temporary};
  write_map_tables(temporary, map, features);
  replace_folder(folder, temporary);
  cleanup.armed = false;
}

SavedMap read_map(const fs::path& folder) {
  std::error_code ec;
  if (!path_taken(folder)) recover_folder(folder, is_saloam_map);  // a replacement killed between its renames
  if (!fs::is_directory(folder, ec)) {
    std::string leftovers;
    for (const fs::path& l : folder_leftovers(folder)) leftovers += (leftovers.empty() ? "" : ", ") + l.string();
    throw InputError(folder, path_taken(folder) ? "is not a folder: a saved map is a folder (map.json, ...)"
                     : leftovers.empty()        ? "not found"
                                                : "not found; a killed writer left " + leftovers);
  }
  SavedMap map;
  map.folder = folder;
  const fs::path manifest_file = folder / "map.json";
  map.manifest = parse_map_manifest(read_file(manifest_file, kMaxManifestBytes, "map manifest"), manifest_file);
  read_map_config(folder, map);
  const fs::path keyframes_file = folder / "keyframes.bin";
  map.keyframes = parse_map_keyframes(bytes_of(read_table(folder, map.manifest, "keyframes.bin", MapTable::kKeyframes, map.config)), keyframes_file);
  if (map.keyframes.size() != map.manifest.keyframes) {
    throw InputError(keyframes_file, fmt::format("{} keyframes, map.json says {}", map.keyframes.size(), map.manifest.keyframes));
  }
  check_sessions(map, keyframes_file);
  const fs::path edges_file = folder / "edges.bin";
  map.edges = parse_map_edges(bytes_of(read_table(folder, map.manifest, "edges.bin", MapTable::kEdges, map.config)), map.keyframes.size(), edges_file);
  if (map.edges.size() != map.manifest.edges) {
    throw InputError(edges_file, fmt::format("{} edges, map.json says {}", map.edges.size(), map.manifest.edges));
  }
  check_graph(map, edges_file);
  const fs::path places_file = folder / "places.bin";
  map.places = parse_map_places(bytes_of(read_table(folder, map.manifest, "places.bin", MapTable::kPlaces, map.config)), map.config, places_file);
  if (map.places.size() != map.keyframes.size()) {
    throw InputError(places_file, fmt::format("{} descriptors for {} keyframes", map.places.size(), map.keyframes.size()));
  }
  if (map.manifest.version >= 3) {
    map.feature_digests = parse_map_digests(bytes_of(read_table(folder, map.manifest, "digests.bin", MapTable::kDigests, map.config)), map.keyframes.size(),
                                            folder / "digests.bin");
  }
  check_place_descriptors(map, places_file);
  return map;
}

StoredFeatures read_map_features(const fs::path& folder, std::size_t keyframe) {
  const fs::path file = map_features_path(folder, keyframe);
  return parse_map_features(bytes_of(read_file(file, checked_table_size(file, MapTable::kFeatures, SaloamConfig{}), "map file")), file);
}

StoredFeatures read_map_features(const SavedMap& map, std::size_t keyframe) {
  const fs::path file = map_features_path(map.folder, keyframe);
  const std::string text = read_file(file, checked_table_size(file, MapTable::kFeatures, map.config), "map file");
  if (keyframe < map.feature_digests.size() && fnv1a64(text) != map.feature_digests[keyframe]) {
    std::string id;
    try {
      id = parse_map_manifest(read_file(map.folder / "map.json", kMaxManifestBytes, "map manifest"), map.folder / "map.json").id;
    } catch (const InputError&) {
      id = "unreadable";
    }
    throw InputError(file, fmt::format("map replaced or changed under this run: the file's digest is not the one the "
                                       "map listed when the run read it ({}; map id {} then, {} now)",
                                       map.folder.string(), map.manifest.id.empty() ? "none" : map.manifest.id,
                                       id.empty() ? "none" : id));
  }
  return parse_map_features(bytes_of(text), file);
}

std::uintmax_t map_disk_bytes(const fs::path& folder) {
  std::uintmax_t bytes = 0;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file(ec)) bytes += it->file_size(ec);
  }
  return bytes;
}

}  // namespace saloam
