// A saved map's manifest, map.json (docs/map_format.md): its encoder and the
// parser that checks every field; the tables are map_format.cpp.
#include "saloam/maps/map_format.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"

namespace fs = std::filesystem;

namespace saloam {

namespace {

std::vector<double> pose_numbers(const Pose& pose) {
  std::vector<double> v(12);
  pose_to_3x4(pose, v.data());
  return v;
}

// "velo_to_cam": 12 finite numbers (at most 1000), an orthonormal rotation.
Pose parse_velo_to_cam(const nlohmann::json& tr, const fs::path& origin) {
  if (!tr.is_array() || tr.size() != 12) throw InputError(origin, "\"velo_to_cam\" is not 12 numbers");
  double v[12];
  for (std::size_t i = 0; i < 12; ++i) {
    if (!tr[i].is_number() || !std::isfinite(tr[i].get<double>()) || std::abs(tr[i].get<double>()) > 1e3) {
      throw InputError(origin, "\"velo_to_cam\" holds a value that is not a finite number of at most 1000");
    }
    v[i] = tr[i].get<double>();
  }
  Pose tr_pose = pose_from_3x4(v);
  const double error = orthonormality_error(tr_pose.linear());
  if (!(error <= kRotationTolerance) || tr_pose.linear().determinant() <= 0) {
    throw InputError(origin, "\"velo_to_cam\": the rotation is not orthonormal");
  }
  return orthonormalized(tr_pose);
}

// A session's "up": three finite numbers of unit length (within 1e-3).
template <class Bad>
Eigen::Vector3d parse_up(const nlohmann::json& up, const Bad& bad) {
  if (!up.is_array() || up.size() != 3 || !std::all_of(up.begin(), up.end(), [](const auto& v) { return v.is_number(); })) {
    throw bad("\"up\" is not three numbers");
  }
  const Eigen::Vector3d u(up[0].get<double>(), up[1].get<double>(), up[2].get<double>());
  if (!u.allFinite() || std::abs(u.norm() - 1.0) > 1e-3) throw bad("\"up\" is not a unit vector");
  return u.normalized();
}

// Version 2's "sessions" (each with source, first_frame, keyframes, linked;
// the first linked; keyframes summing to the map's) and "cross_session_loops".
void parse_sessions(const nlohmann::json& j, MapManifest& m, const fs::path& origin) {
  const auto sessions = j.find("sessions");
  if (sessions == j.end() || !sessions->is_array() || sessions->empty() || sessions->size() > m.keyframes) {
    throw InputError(origin, "\"sessions\" is not a list of 1 to \"keyframes\" sessions");
  }
  std::uint64_t keyframes = 0;
  for (std::size_t i = 0; i < sessions->size(); ++i) {
    const nlohmann::json& s = (*sessions)[i];
    const auto bad = [&](const char* what) {
      return InputError(origin, fmt::format("session {}: {}", i, what));
    };
    if (!s.is_object()) throw bad("not a JSON object");
    const auto source = s.find("source"), first = s.find("first_frame"), count = s.find("keyframes"),
               linked = s.find("linked");
    if (source == s.end() || !source->is_string()) throw bad("\"source\" is not a string");
    if (first == s.end() || !first->is_number_unsigned()) throw bad("\"first_frame\" is not a non-negative integer");
    if (count == s.end() || !count->is_number_unsigned() || count->get<std::uint64_t>() == 0 ||
        count->get<std::uint64_t>() > m.keyframes) {
      throw bad("\"keyframes\" is not a count of 1 to the map's keyframes");
    }
    if (linked == s.end() || !linked->is_boolean()) throw bad("\"linked\" is not true or false");
    if (i == 0 && !linked->get<bool>()) throw bad("the first session defines the map frame: it is linked");
    m.sessions.push_back({source->get<std::string>(), first->get<std::uint64_t>(), count->get<std::uint64_t>(),
                          linked->get<bool>()});
    // "up": optional (maps saved before it was recorded: the sensor's z).
    if (const auto up = s.find("up"); up != s.end()) m.sessions.back().up = parse_up(*up, bad);
    keyframes += m.sessions.back().keyframes;
  }
  if (keyframes != m.keyframes) {
    throw InputError(origin, fmt::format("the sessions hold {} keyframes, \"keyframes\" says {}", keyframes, m.keyframes));
  }
  const auto loops = j.find("cross_session_loops");
  if (loops == j.end() || !loops->is_number_unsigned() || loops->get<std::uint64_t>() > m.loop_edges) {
    throw InputError(origin, "\"cross_session_loops\" is not a count of at most \"loop_edges\"");
  }
  m.cross_session_loops = loops->get<std::uint64_t>();
}

}  // namespace

std::string encode_map_manifest(const MapManifest& m) {
  nlohmann::ordered_json j;
  j["format"] = kMapFormatName;
  j["version"] = m.version;
  j["frame"] = m.frame;
  j["detector"] = m.detector;
  j["sensor"] = m.sensor;
  j["source"] = m.source;
  j["first_frame"] = m.first_frame;
  j["keyframes"] = m.keyframes;
  j["edges"] = m.edges;
  j["loop_edges"] = m.loop_edges;
  j["camera_frame_outputs"] = m.camera_frame_outputs;
  j["velo_to_cam"] = pose_numbers(m.velo_to_cam);
  j["sessions"] = nlohmann::ordered_json::array();
  for (const MapSession& s : m.sessions) {
    j["sessions"].push_back(
        {{"source", s.source}, {"first_frame", s.first_frame}, {"keyframes", s.keyframes}, {"linked", s.linked},
         {"up", {s.up.x(), s.up.y(), s.up.z()}}});
  }
  j["cross_session_loops"] = m.cross_session_loops;
  j["files"] = {{"config", "config.yaml"},
                {"keyframes", "keyframes.bin"},
                {"edges", "edges.bin"},
                {"places", "places.bin"},
                {"features", "features/NNNNNN.bin"},
                {"digests", "digests.bin"}};
  j["id"] = m.id;
  j["digest"] = "fnv1a-64";
  j["digests"] = nlohmann::ordered_json::object();
  for (const auto& [file, digest] : m.digests) j["digests"][file] = digest_text(digest);
  return j.dump(2) + '\n';
}

std::string digest_text(std::uint64_t digest) { return fmt::format("{:016x}", digest); }

std::vector<MapSession> map_sessions(const SavedMap& map) {
  if (!map.manifest.sessions.empty()) return map.manifest.sessions;
  return {MapSession{map.manifest.source, map.manifest.first_frame, map.keyframes.size(), true}};
}

namespace {
// The manifest's fields, each checked as it is read: a missing or mistyped
// one is an InputError naming the file.
class ManifestFields {
 public:
  ManifestFields(const nlohmann::json& j, const fs::path& origin) : j_(j), origin_(origin) {}
  [[nodiscard]] const nlohmann::json& field(const char* key) const {
    const auto it = j_.find(key);
    if (it == j_.end()) throw InputError(origin_, fmt::format("no \"{}\"", key));
    return *it;
  }
  [[nodiscard]] std::string string_of(const char* key) const {
    const auto& v = field(key);
    if (!v.is_string()) throw InputError(origin_, fmt::format("\"{}\" is not a string", key));
    return v.get<std::string>();
  }
  [[nodiscard]] std::uint64_t count_of(const char* key, std::uint64_t max) const {
    const auto& v = field(key);
    if (!v.is_number_unsigned()) throw InputError(origin_, fmt::format("\"{}\" is not a non-negative integer", key));
    const auto n = v.get<std::uint64_t>();
    if (n > max) throw InputError(origin_, fmt::format("\"{}\" is {}, beyond {}", key, n, max));
    return n;
  }

 private:
  const nlohmann::json& j_;
  const fs::path& origin_;
};

// Version 3's "id" (32 hexadecimal digits), "digest" and "digests" (one of
// 16 hexadecimal digits per digested file).
void parse_digests(const ManifestFields& fields, MapManifest& m, const fs::path& origin) {
  m.id = fields.string_of("id");
  if (m.id.size() != 32 || m.id.find_first_not_of("0123456789abcdef") != std::string::npos) {
    throw InputError(origin, "\"id\" is not 32 hexadecimal digits");
  }
  if (fields.string_of("digest") != "fnv1a-64") throw InputError(origin, "\"digest\" is not \"fnv1a-64\"");
  const auto& digests = fields.field("digests");
  if (!digests.is_object()) throw InputError(origin, "\"digests\" is not an object");
  for (const std::string_view file : kMapDigestedFiles) {
    const auto it = digests.find(std::string(file));
    if (it == digests.end() || !it->is_string() || it->get<std::string>().size() != 16 ||
        it->get<std::string>().find_first_not_of("0123456789abcdef") != std::string::npos) {
      throw InputError(origin, fmt::format("\"digests\" has no digest (16 hexadecimal digits) of {}", file));
    }
    m.digests[std::string(file)] = std::stoull(it->get<std::string>(), nullptr, 16);
  }
}

// "format", "version" (one this saloam reads) and "detector" (a known one).
void parse_identity(const ManifestFields& fields, MapManifest& m, const fs::path& origin) {
  if (fields.string_of("format") != kMapFormatName) {
    throw InputError(origin, fmt::format("\"format\" is not \"{}\": not a saloam map", kMapFormatName));
  }
  const auto& version = fields.field("version");
  if (!version.is_number_unsigned() || version.get<std::uint64_t>() < kMapFormatOldestVersion ||
      version.get<std::uint64_t>() > kMapFormatVersion) {
    throw InputError(origin, fmt::format("format version {}; this saloam reads versions {} to {}", version.dump(),
                                         kMapFormatOldestVersion, kMapFormatVersion));
  }
  m.version = version.get<std::uint32_t>();
  m.detector = fields.string_of("detector");
  try {
    (void)parse_place_detector(m.detector);
  } catch (const ConfigError& e) {
    throw InputError(origin, e.what());
  }
}
}  // namespace

MapManifest parse_map_manifest(std::string_view text, const fs::path& origin) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(origin, fmt::format("not valid JSON: {}", e.what()));
  }
  if (!j.is_object()) throw InputError(origin, "not a JSON object");
  const ManifestFields fields(j, origin);
  MapManifest m;
  parse_identity(fields, m, origin);
  m.sensor = fields.string_of("sensor");
  m.source = fields.string_of("source");
  m.frame = fields.string_of("frame");
  m.first_frame = fields.count_of("first_frame", std::uint64_t{1} << 53);
  m.keyframes = fields.count_of("keyframes", kMaxMapKeyframes);
  if (m.keyframes == 0) throw InputError(origin, "the map has no keyframe");
  m.edges = fields.count_of("edges", 100 * kMaxMapKeyframes);
  m.loop_edges = fields.count_of("loop_edges", m.edges);
  const auto& camera = fields.field("camera_frame_outputs");
  if (!camera.is_boolean()) throw InputError(origin, "\"camera_frame_outputs\" is not true or false");
  m.camera_frame_outputs = camera.get<bool>();
  m.velo_to_cam = parse_velo_to_cam(fields.field("velo_to_cam"), origin);
  if (m.version >= 2) {
    parse_sessions(j, m, origin);
  } else {
    m.sessions = {MapSession{m.source, m.first_frame, m.keyframes, true}};
  }
  if (m.version >= 3) parse_digests(fields, m, origin);
  return m;
}

}  // namespace saloam
