#pragma once
// The saved map (`saloam slam ... --save-map MAP`, docs/map_format.md): what a
// later run needs to localise in the map or to continue it. A folder:
//
//   MAP/map.json              manifest: format, version, counts, detector, sensor, origin of the data
//   MAP/config.yaml           the configuration the map was made with (config_to_yaml)
//   MAP/keyframes.bin         per keyframe: frame, time, path length, optimised pose, odometry pose, session
//   MAP/edges.bin             the pose graph's edges: nodes, kind, measurement, information (6x6)
//   MAP/places.bin            per keyframe: its place descriptor (Scan Context, SSC, SGPR graph)
//   MAP/features/NNNNNN.bin   per keyframe: its labelled feature cloud (sensor frame), read on demand
//
// Binary files are little-endian and start with the same 24-byte header:
// magic "SALOAMAP", the format version (uint32), the table's kind (uint32)
// and its record count (uint64). Poses are T_map<-sensor, the map frame being
// the LiDAR frame of the first keyframe (a session not linked to the first
// keeps its own frame: MapSession::linked). A map is written into a temporary
// folder beside MAP and renamed into place when complete (an earlier map of
// the same name is replaced only then); a folder that is not a saloam map is
// never replaced.
//
// Reading validates everything (the version, counts against the manifest and
// the file sizes, finite values, orthonormal rotations, positive-definite
// information, node and class indices in range) and throws InputError naming
// the file and the problem. The features of a keyframe are read only when a
// run asks for them (MapFeatures): a large map does not have to fit in memory.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/slam/pose_graph.hpp"
#include "saloam/slam/slam_system.hpp"

namespace saloam {

/// Version written; the reader also reads every version from kMapFormatOldestVersion
/// (version 1: one session, no session per keyframe; version 2: no map id
/// and no digests, so nothing is checked against them).
inline constexpr std::uint32_t kMapFormatVersion = 3;
inline constexpr std::uint32_t kMapFormatOldestVersion = 1;
inline constexpr std::string_view kMapFormatName = "saloam-map";
inline constexpr std::string_view kMapMagic = "SALOAMAP";  ///< 8 bytes, no terminator in the files

/// Table kinds of the binary files' headers.
enum class MapTable : std::uint32_t { kKeyframes = 1, kEdges = 2, kPlaces = 3, kFeatures = 4, kDigests = 5 };

/// The files of a map whose digests map.json holds (version 3); each
/// keyframe's features file has its digest in digests.bin.
inline constexpr std::string_view kMapDigestedFiles[] = {"config.yaml", "keyframes.bin", "edges.bin", "places.bin",
                                                         "digests.bin"};

/// Bounds the reader enforces (a map beyond them is refused, naming the file).
inline constexpr double kMaxMapCoordinate = 1.0e7;     ///< [m] pose translations
inline constexpr float kMaxFeatureCoordinate = 1.0e4F;  ///< [m] feature points, sensor frame
inline constexpr std::size_t kMaxMapKeyframes = 10'000'000;
inline constexpr std::size_t kMaxKeyframeFeatures = 10'000'000;  ///< points per keyframe
inline constexpr double kMaxInformation = 1.0e12;

/// One keyframe as the map keeps it (its features are read apart).
struct MapKeyframe {
  std::uint64_t frame = 0;       ///< frame of the mapping run (processing order)
  double timestamp = 0;          ///< [s] of the mapping run
  double travelled = 0;          ///< [m] odometry path length up to it
  Pose pose = Pose::Identity();  ///< optimised T_map<-sensor
  Pose odometry_pose = Pose::Identity();  ///< the mapping run's odometry pose
  std::uint32_t session = 0;     ///< the drive (MapManifest::sessions) it belongs to
};

/// One drive of a map (a `slam` run; joined by `slam --map` or `merge`).
struct MapSession {
  std::string source;             ///< where its scans came from (informational)
  std::uint64_t first_frame = 0;  ///< the source's frame of its keyframe frame 0
  std::uint64_t keyframes = 0;
  /// Its poses are in the map frame, tied to session 0 by verified loops
  /// (session 0 always is); false: in its own frame (the LiDAR frame of its
  /// first keyframe), a component of the pose graph of its own.
  bool linked = true;
  /// Up (against gravity, unit) in the frame of its odometry poses
  /// (MapKeyframe::odometry_pose), as its run measured or was told it
  /// (odometry/gravity.hpp): its keyframes were described level, turned by
  /// level_rotation(odometry_pose^T up). The sensor's z for maps saved
  /// before up was recorded.
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
};

/// The manifest (map.json).
struct MapManifest {
  std::uint32_t version = kMapFormatVersion;
  std::string detector;         ///< loop.detector the descriptors were made for
  std::string sensor;           ///< the sensor profile's name ("" when none)
  std::string source;           ///< where the mapping run's scans came from (informational)
  std::uint64_t first_frame = 0;  ///< the source's frame of keyframe frame 0
  std::string frame = "LiDAR frame of the first keyframe (x forward, y left, z up), metres";
  std::uint64_t keyframes = 0;
  std::uint64_t edges = 0;
  std::uint64_t loop_edges = 0;
  bool camera_frame_outputs = false;  ///< the mapping run had a Tr (calib.txt)
  Pose velo_to_cam = Pose::Identity();  ///< that Tr (identity when none)
  /// The drives, in keyframe order (keyframes of session s follow those of
  /// s-1). Version 1 maps read as one session (source, first_frame).
  std::vector<MapSession> sessions;
  std::uint64_t cross_session_loops = 0;  ///< loop edges between keyframes of different sessions
  /// The map's identity (version 3): 32 hexadecimal digits drawn at random
  /// each time a map is saved; "" for older versions.
  std::string id;
  /// FNV-1a 64 digest (core/hash.hpp) of each of kMapDigestedFiles (version
  /// 3; empty for older versions).
  std::map<std::string, std::uint64_t> digests;
};

/// Everything of a map but the feature clouds: what a run holds in memory.
struct SavedMap {
  std::filesystem::path folder;
  MapManifest manifest;
  SaloamConfig config;
  std::vector<MapKeyframe> keyframes;
  std::vector<PoseGraphEdge> edges;
  std::vector<PlaceDescriptor> places;  ///< one per keyframe (empty parts: not used by the detector)
  /// Digest of each keyframe's features file (digests.bin; empty for a map
  /// before version 3): a features file read later is checked against it.
  std::vector<std::uint64_t> feature_digests;
};

/// Writes `map` into `folder` (see above): features(k) gives keyframe k's
/// features. InputError naming the file when anything cannot be written, or
/// when `folder` exists and is not a saloam map.
void write_map(const std::filesystem::path& folder, const SavedMap& map,
               const std::function<const StoredFeatures&(std::size_t)>& features);

/// InputError when `folder` exists and is not a saloam map (write_map would
/// refuse it): a run checks before it starts.
void check_map_destination(const std::filesystem::path& folder);

/// Reads and validates map.json, config.yaml, keyframes.bin, edges.bin and
/// places.bin of the map in `folder` (not the features). InputError naming
/// the file and the problem.
SavedMap read_map(const std::filesystem::path& folder);

/// The map's sessions: the manifest's list, or for a version 1 map (no
/// list) one linked session of every keyframe, from the manifest's source
/// and first_frame.
std::vector<MapSession> map_sessions(const SavedMap& map);

/// Path of keyframe k's feature file.
std::filesystem::path map_features_path(const std::filesystem::path& folder, std::size_t keyframe);
/// Reads and validates one keyframe's features.
StoredFeatures read_map_features(const std::filesystem::path& folder, std::size_t keyframe);
/// The same from the map `map` read (read_map), checked against its digest:
/// a file that no longer matches (another run replaced the map, or the file
/// was changed) is an InputError "map replaced or changed under this run".
StoredFeatures read_map_features(const SavedMap& map, std::size_t keyframe);

/// The bytes at a table file's start that map_table_max_bytes looks at (the
/// 24-byte header; a features file's point counts after it).
inline constexpr std::size_t kMapTableHeadBytes = 40;
/// The most bytes a table file may hold, from its first bytes `head` (up to
/// kMapTableHeadBytes): the header checked (magic, version, kind `table`),
/// then its record count times max_map_record_bytes (a features file: its
/// exact size from its point counts). A larger file is refused before it is
/// read (issue #39). InputError naming `origin` for a bad header.
std::uint64_t map_table_max_bytes(std::span<const std::byte> head, MapTable table, const SaloamConfig& config,
                                  const std::filesystem::path& origin);
/// The most bytes one record of `table` takes in a map made with `config`.
std::uint64_t max_map_record_bytes(MapTable table, const SaloamConfig& config);

// The parsers behind the readers (also what the fuzz harness feeds): each
// takes the bytes of one file and `origin`, the file named in errors.
MapManifest parse_map_manifest(std::string_view text, const std::filesystem::path& origin);
std::vector<MapKeyframe> parse_map_keyframes(std::span<const std::byte> bytes, const std::filesystem::path& origin);
/// `nodes`: the keyframe count (edges must join two of them).
std::vector<PoseGraphEdge> parse_map_edges(std::span<const std::byte> bytes, std::size_t nodes,
                                           const std::filesystem::path& origin);
/// Descriptor sizes are checked against `config` (loop.ssc) and the Scan Context defaults.
std::vector<PlaceDescriptor> parse_map_places(std::span<const std::byte> bytes, const SaloamConfig& config,
                                              const std::filesystem::path& origin);
StoredFeatures parse_map_features(std::span<const std::byte> bytes, const std::filesystem::path& origin);
/// digests.bin: one FNV-1a 64 digest per keyframe's features file (`keyframes` of them).
std::vector<std::uint64_t> parse_map_digests(std::span<const std::byte> bytes, std::size_t keyframes,
                                             const std::filesystem::path& origin);

// The encoders (write_map uses them; tests and the fuzz corpus too).
std::string encode_map_manifest(const MapManifest& manifest);
std::vector<std::byte> encode_map_keyframes(std::span<const MapKeyframe> keyframes);
std::vector<std::byte> encode_map_edges(std::span<const PoseGraphEdge> edges);
std::vector<std::byte> encode_map_places(std::span<const PlaceDescriptor> places);
std::vector<std::byte> encode_map_features(const StoredFeatures& features);
std::vector<std::byte> encode_map_digests(std::span<const std::uint64_t> digests);
/// A digest as the manifest writes it (16 lower-case hexadecimal digits).
std::string digest_text(std::uint64_t digest);

/// Bytes the map takes on disk (every file in the folder).
std::uintmax_t map_disk_bytes(const std::filesystem::path& folder);

}  // namespace saloam
