// A saved map's folder (docs/map_format.md): written whole into a temporary
// folder beside it and renamed into place, read back table by table with
// every count and reference checked; the tables' bytes are map_format.cpp's.
#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
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

std::vector<std::byte> read_table(const fs::path& file) {
  const std::string text = read_file(file, kMaxTableBytes, "map file");
  std::vector<std::byte> bytes(text.size());
  if (!text.empty()) std::memcpy(bytes.data(), text.data(), text.size());
  return bytes;
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

// Temporary folders of killed writers of `target` ("NAME.partial-PID.N"
// whose process is gone) are removed.
void remove_stale_partials(const fs::path& target) {
  std::error_code ec;
  const fs::path parent = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  const std::string prefix = target.filename().string() + ".partial-";
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (!name.starts_with(prefix) || !is_partial_output_name(name) || !it->is_directory(ec)) continue;
    const std::string pid_text = name.substr(prefix.size(), name.find('.', prefix.size()) - prefix.size());
    const long pid = std::strtol(pid_text.c_str(), nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) fs::remove_all(it->path(), ec);
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

// A fresh name for a temporary folder beside `target` ("NAME.partial-PID.N").
fs::path partial_folder_name(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  return target.string() + fmt::format(".partial-{}.{}", static_cast<long>(::getpid()), counter.fetch_add(1));
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
  manifest.loop_edges = static_cast<std::uint64_t>(
      std::count_if(map.edges.begin(), map.edges.end(), [](const PoseGraphEdge& e) { return e.kind == EdgeKind::kLoop; }));
  manifest.detector = map.config.loop.detector;
  manifest.sessions = counted_sessions(map);
  manifest.cross_session_loops = static_cast<std::uint64_t>(
      std::count_if(map.edges.begin(), map.edges.end(), [&](const PoseGraphEdge& e) {
        return e.kind == EdgeKind::kLoop && map.keyframes[e.from].session != map.keyframes[e.to].session;
      }));
  return manifest;
}

// Every file of the map into `folder`, the manifest last: a folder without one is no map.
void write_map_tables(const fs::path& folder, const SavedMap& map,
                      const std::function<const StoredFeatures&(std::size_t)>& features) {
  create_folder(folder / "features");
  const MapManifest manifest = manifest_to_write(map);
  write_file_atomically(folder / "config.yaml", config_to_yaml(map.config));
  const auto put = [&](const fs::path& file, const std::vector<std::byte>& bytes) {
    write_file_atomically(file, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  };
  put(folder / "keyframes.bin", encode_map_keyframes(map.keyframes));
  put(folder / "edges.bin", encode_map_edges(map.edges));
  put(folder / "places.bin", encode_map_places(map.places));
  for (std::size_t k = 0; k < map.keyframes.size(); ++k) {
    put(map_features_path(folder, k), encode_map_features(features(k)));
  }
  write_file_atomically(folder / "map.json", encode_map_manifest(manifest));
}

// Renames the finished `temporary` to `folder`. An earlier map of this name
// goes aside first, and away once the new one is in place (back, when that fails).
void replace_folder(const fs::path& folder, const fs::path& temporary) {
  std::error_code ec;
  fs::path previous;
  if (path_taken(folder)) {
    previous = partial_folder_name(folder);
    fs::rename(folder, previous, ec);
    if (ec) throw InputError(folder, fmt::format("cannot move the earlier map aside: {}", ec.message()));
  }
  fs::rename(temporary, folder, ec);
  if (ec) {
    std::error_code ignored;
    if (!previous.empty()) fs::rename(previous, folder, ignored);
    throw InputError(folder, fmt::format("cannot put the map in place: {}", ec.message()));
  }
  if (!previous.empty()) fs::remove_all(previous, ec);
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
  remove_stale_partials(folder);
  const fs::path temporary = partial_folder_name(folder);
  RemoveOnFailure cleanup{temporary};
  write_map_tables(temporary, map, features);
  replace_folder(folder, temporary);
  cleanup.armed = false;
}

SavedMap read_map(const fs::path& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    throw InputError(folder, path_taken(folder) ? "is not a folder: a saved map is a folder (map.json, ...)"
                                                : "not found");
  }
  SavedMap map;
  map.folder = folder;
  const fs::path manifest_file = folder / "map.json";
  map.manifest = parse_map_manifest(read_file(manifest_file, kMaxManifestBytes, "map manifest"), manifest_file);
  const fs::path config_file = folder / "config.yaml";
  try {
    map.config = load_config(config_file);
  } catch (const ConfigError& e) {
    throw InputError(config_file, e.what());
  }
  if (map.config.loop.detector != map.manifest.detector) {
    throw InputError(manifest_file, fmt::format("detector \"{}\", but config.yaml says loop.detector \"{}\"",
                                                map.manifest.detector, map.config.loop.detector));
  }
  const fs::path keyframes_file = folder / "keyframes.bin";
  map.keyframes = parse_map_keyframes(read_table(keyframes_file), keyframes_file);
  if (map.keyframes.size() != map.manifest.keyframes) {
    throw InputError(keyframes_file, fmt::format("{} keyframes, map.json says {}", map.keyframes.size(), map.manifest.keyframes));
  }
  check_sessions(map, keyframes_file);
  const fs::path edges_file = folder / "edges.bin";
  map.edges = parse_map_edges(read_table(edges_file), map.keyframes.size(), edges_file);
  if (map.edges.size() != map.manifest.edges) {
    throw InputError(edges_file, fmt::format("{} edges, map.json says {}", map.edges.size(), map.manifest.edges));
  }
  const fs::path places_file = folder / "places.bin";
  map.places = parse_map_places(read_table(places_file), map.config, places_file);
  if (map.places.size() != map.keyframes.size()) {
    throw InputError(places_file, fmt::format("{} descriptors for {} keyframes", map.places.size(), map.keyframes.size()));
  }
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
  return map;
}

StoredFeatures read_map_features(const fs::path& folder, std::size_t keyframe) {
  const fs::path file = map_features_path(folder, keyframe);
  return parse_map_features(read_table(file), file);
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
