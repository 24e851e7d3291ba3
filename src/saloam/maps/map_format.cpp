// The bytes of a saved map's tables (docs/map_format.md): encoders and the
// parsers that check every field; the manifest is map_manifest.cpp, the
// folder map_folder.cpp.
#include "saloam/maps/map_format.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/place/semantic_graph.hpp"

namespace fs = std::filesystem;

namespace saloam {

static_assert(std::endian::native == std::endian::little, "the map format is little-endian; this build is not");

namespace {

constexpr std::size_t kHeaderBytes = 24;
constexpr std::size_t kMaxGraphNodes = 100'000;
constexpr std::size_t kMaxSscPoints = 10'000'000;
constexpr std::uint32_t kHasScanContext = 1, kHasSsc = 2, kHasSgpr = 4;
constexpr std::uint32_t kKnownPlaceFlags = kHasScanContext | kHasSsc | kHasSgpr;
constexpr double kMaxTimestamp = 1e10;  // [s]

// ---- writing ----

class ByteWriter {
 public:
  template <class T>
  void put(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const std::byte*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void put_pose(const Pose& pose) {
    double v[12];
    pose_to_3x4(pose, v);
    for (const double x : v) put(x);
  }
  void header(MapTable table, std::uint64_t count) {
    for (const char c : kMapMagic) put(c);
    put(kMapFormatVersion);
    put(static_cast<std::uint32_t>(table));
    put(count);
  }
  std::vector<std::byte> take() { return std::move(bytes_); }

 private:
  std::vector<std::byte> bytes_;
};

// ---- reading ----

class ByteReader {
 public:
  ByteReader(std::span<const std::byte> bytes, const fs::path& origin) : bytes_(bytes), origin_(origin) {}

  template <class T>
  T get(std::string_view what) {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T), what);
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  double finite(std::string_view what, double bound) {
    const auto v = get<double>(what);
    if (!std::isfinite(v) || std::abs(v) > bound) fail(fmt::format("{} is {} (not finite, or beyond {:g})", what, v, bound));
    return v;
  }
  float finite_float(std::string_view what, float bound) {
    const auto v = get<float>(what);
    if (!std::isfinite(v) || std::abs(v) > bound) fail(fmt::format("{} is {} (not finite, or beyond {:g})", what, v, bound));
    return v;
  }
  Pose pose(std::string_view what) {
    double v[12];
    for (int i = 0; i < 12; ++i) v[i] = finite(what, kMaxMapCoordinate);
    const Pose pose = pose_from_3x4(v);
    const double error = orthonormality_error(pose.linear());
    if (!(error <= kRotationTolerance) || pose.linear().determinant() <= 0) {
      fail(fmt::format("{}: the rotation is not orthonormal (error {:.3g})", what, error));
    }
    return orthonormalized(pose);
  }
  /// A count of items of at least `item_bytes` each that the rest of the file can hold.
  std::size_t count(std::uint64_t n, std::size_t item_bytes, std::string_view what, std::size_t max) {
    if (n > max) fail(fmt::format("{} {} exceed the limit of {}", n, what, max));
    if (item_bytes > 0 && n > remaining() / item_bytes) {
      fail(fmt::format("truncated: {} {} need at least {} bytes, {} are left", n, what, n * item_bytes, remaining()));
    }
    return static_cast<std::size_t>(n);
  }
  std::uint64_t header(MapTable expected) {
    need(kHeaderBytes, "the header");
    if (std::memcmp(bytes_.data(), kMapMagic.data(), kMapMagic.size()) != 0) {
      fail("not a saloam map file (no SALOAMAP magic)");
    }
    at_ = kMapMagic.size();
    version_ = get<std::uint32_t>("version");
    if (version_ < kMapFormatOldestVersion || version_ > kMapFormatVersion) {
      fail(fmt::format("format version {}; this saloam reads versions {} to {}", version_, kMapFormatOldestVersion,
                       kMapFormatVersion));
    }
    const auto table = get<std::uint32_t>("table kind");
    if (table != static_cast<std::uint32_t>(expected)) {
      fail(fmt::format("holds table kind {}, expected {}", table, static_cast<std::uint32_t>(expected)));
    }
    return get<std::uint64_t>("record count");
  }
  void finish() {
    if (at_ != bytes_.size()) fail(fmt::format("{} bytes of trailing data after the last record", bytes_.size() - at_));
  }
  [[nodiscard]] std::size_t remaining() const { return bytes_.size() - at_; }
  [[nodiscard]] std::uint32_t version() const { return version_; }
  [[noreturn]] void fail(const std::string& problem) const { throw InputError(origin_, problem); }

 private:
  void need(std::size_t n, std::string_view what) {
    if (n > remaining()) fail(fmt::format("truncated: {} needs {} bytes at offset {}, {} are left", what, n, at_, remaining()));
  }
  std::span<const std::byte> bytes_;
  const fs::path& origin_;
  std::size_t at_ = 0;
  std::uint32_t version_ = 0;
};

std::string_view edge_kind_name(EdgeKind kind) { return kind == EdgeKind::kLoop ? "loop" : "odometry"; }

}  // namespace

// ---------------------------------------------------------------- encoders

std::vector<std::byte> encode_map_digests(std::span<const std::uint64_t> digests) {
  ByteWriter w;
  w.header(MapTable::kDigests, digests.size());
  for (const std::uint64_t d : digests) w.put(d);
  return w.take();
}

std::vector<std::byte> encode_map_keyframes(std::span<const MapKeyframe> keyframes) {
  ByteWriter w;
  w.header(MapTable::kKeyframes, keyframes.size());
  for (const auto& k : keyframes) {
    w.put(k.frame);
    w.put(k.timestamp);
    w.put(k.travelled);
    w.put_pose(k.pose);
    w.put_pose(k.odometry_pose);
    w.put(k.session);
  }
  return w.take();
}

std::vector<std::byte> encode_map_edges(std::span<const PoseGraphEdge> edges) {
  ByteWriter w;
  w.header(MapTable::kEdges, edges.size());
  for (const auto& e : edges) {
    w.put(static_cast<std::uint32_t>(e.from));
    w.put(static_cast<std::uint32_t>(e.to));
    w.put(static_cast<std::uint32_t>(e.kind == EdgeKind::kLoop ? 1 : 0));
    w.put_pose(e.measured);
    for (int r = 0; r < 6; ++r)
      for (int c = r; c < 6; ++c) w.put(e.information(r, c));
  }
  return w.take();
}

std::vector<std::byte> encode_map_places(std::span<const PlaceDescriptor> places) {
  ByteWriter w;
  w.header(MapTable::kPlaces, places.size());
  for (const auto& p : places) {
    const bool sc = p.context.descriptor.size() > 0;
    const bool ssc = !p.ssc.key_range.empty();
    const bool sgpr = !p.graph.nodes.empty() || p.embedding.squaredNorm() > 0;
    w.put(static_cast<std::uint32_t>((sc ? kHasScanContext : 0) | (ssc ? kHasSsc : 0) | (sgpr ? kHasSgpr : 0)));
    if (sc) {
      w.put(static_cast<std::uint32_t>(p.context.descriptor.rows()));
      w.put(static_cast<std::uint32_t>(p.context.descriptor.cols()));
      for (Eigen::Index i = 0; i < p.context.descriptor.size(); ++i) w.put(p.context.descriptor.data()[i]);
    }
    if (ssc) {
      w.put(static_cast<std::uint32_t>(p.ssc.points.size()));
      for (std::size_t i = 0; i < p.ssc.points.size(); ++i) {
        w.put(p.ssc.points[i].x());
        w.put(p.ssc.points[i].y());
        w.put(p.ssc.codes[i]);
      }
      w.put(static_cast<std::uint32_t>(p.ssc.key_range.size()));
      for (std::size_t i = 0; i < p.ssc.key_range.size(); ++i) {
        w.put(p.ssc.key_range[i]);
        w.put(p.ssc.key_points[i].x());
        w.put(p.ssc.key_points[i].y());
      }
    }
    if (sgpr) {
      w.put(static_cast<std::uint32_t>(p.graph.nodes.size()));
      for (std::size_t i = 0; i < p.graph.nodes.size(); ++i) {
        w.put(static_cast<std::int32_t>(p.graph.nodes[i]));
        for (int a = 0; a < 3; ++a) w.put(p.graph.centers[i][a]);
      }
      for (int i = 0; i < kSgprEmbeddingSize; ++i) w.put(p.embedding[i]);
    }
  }
  return w.take();
}

std::vector<std::byte> encode_map_features(const StoredFeatures& f) {
  ByteWriter w;
  w.header(MapTable::kFeatures, 1);
  w.put(static_cast<std::uint64_t>(f.edge_points.size()));
  w.put(static_cast<std::uint64_t>(f.planar_points.size()));
  const auto cloud = [&](const std::vector<Eigen::Vector3f>& points, const std::vector<ClassIndex>& classes) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      w.put(points[i].x());
      w.put(points[i].y());
      w.put(points[i].z());
      w.put(classes[i]);
    }
  };
  cloud(f.edge_points, f.edge_classes);
  cloud(f.planar_points, f.planar_classes);
  return w.take();
}

// ---------------------------------------------------------------- parsers

std::vector<MapKeyframe> parse_map_keyframes(std::span<const std::byte> bytes, const fs::path& origin) {
  ByteReader r(bytes, origin);
  const std::uint64_t records = r.header(MapTable::kKeyframes);
  const std::size_t record_bytes = 8 + 8 + 8 + 96 + 96 + (r.version() >= 2 ? 4 : 0);
  const std::size_t n = r.count(records, record_bytes, "keyframes", kMaxMapKeyframes);
  std::vector<MapKeyframe> keyframes(n);
  for (std::size_t k = 0; k < n; ++k) {
    MapKeyframe& kf = keyframes[k];
    kf.frame = r.get<std::uint64_t>("frame");
    kf.timestamp = r.finite("timestamp", kMaxTimestamp);
    kf.travelled = r.finite("path length", kMaxMapCoordinate * 100);
    kf.pose = r.pose(fmt::format("keyframe {}: pose", k));
    kf.odometry_pose = r.pose(fmt::format("keyframe {}: odometry pose", k));
    if (r.version() >= 2) kf.session = r.get<std::uint32_t>("session");
    const std::uint32_t previous_session = k > 0 ? keyframes[k - 1].session : 0;
    if (k == 0 ? kf.session != 0 : kf.session != previous_session && kf.session != previous_session + 1) {
      r.fail(fmt::format("keyframe {}: session {} after session {} (sessions follow one another from 0)", k,
                         kf.session, previous_session));
    }
    const bool follows = k > 0 && kf.session == previous_session;  // same session as the one before
    if (follows && kf.frame <= keyframes[k - 1].frame) {
      r.fail(fmt::format("keyframe {}: frame {} does not follow frame {}", k, kf.frame, keyframes[k - 1].frame));
    }
    if (kf.travelled < 0 || (follows && kf.travelled < keyframes[k - 1].travelled)) {
      r.fail(fmt::format("keyframe {}: path length {} decreases or is negative", k, kf.travelled));
    }
  }
  r.finish();
  return keyframes;
}

std::vector<PoseGraphEdge> parse_map_edges(std::span<const std::byte> bytes, std::size_t nodes, const fs::path& origin) {
  ByteReader r(bytes, origin);
  constexpr std::size_t kRecord = 12 + 96 + 21 * 8;
  const std::size_t n = r.count(r.header(MapTable::kEdges), kRecord, "edges", 100 * kMaxMapKeyframes);
  std::vector<PoseGraphEdge> edges(n);
  for (std::size_t k = 0; k < n; ++k) {
    PoseGraphEdge& e = edges[k];
    const auto from = r.get<std::uint32_t>("from"), to = r.get<std::uint32_t>("to");
    const auto kind = r.get<std::uint32_t>("kind");
    if (from >= nodes || to >= nodes || from == to) {
      r.fail(fmt::format("edge {}: nodes {} -> {} (the map has {} keyframes)", k, from, to, nodes));
    }
    if (kind > 1) r.fail(fmt::format("edge {}: kind {} (0 odometry, 1 loop)", k, kind));
    e.from = from;
    e.to = to;
    e.kind = kind == 1 ? EdgeKind::kLoop : EdgeKind::kOdometry;
    e.measured = r.pose(fmt::format("edge {}: measurement", k));
    for (int row = 0; row < 6; ++row) {
      for (int c = row; c < 6; ++c) {
        e.information(row, c) = e.information(c, row) = r.finite(fmt::format("edge {}: information", k), kMaxInformation);
      }
    }
    const Eigen::LLT<Matrix6d> llt(e.information);
    if (llt.info() != Eigen::Success || !(llt.matrixL().toDenseMatrix().diagonal().minCoeff() > 1e-12)) {
      r.fail(fmt::format("edge {} ({} edge {} -> {}): the information is not positive definite", k,
                         edge_kind_name(e.kind), from, to));
    }
  }
  r.finish();
  return edges;
}

namespace {

// One place's Scan Context: its size (which must be this saloam's), then the cells.
ScanContext read_scan_context(ByteReader& r, const std::string& at) {
  const ScanContextConfig sc_config;
  const auto rows = r.get<std::uint32_t>("Scan Context rows"), cols = r.get<std::uint32_t>("Scan Context sectors");
  if (rows != static_cast<std::uint32_t>(sc_config.num_rings) || cols != static_cast<std::uint32_t>(sc_config.num_sectors)) {
    r.fail(fmt::format("{}: Scan Context of {} x {} cells; this saloam makes {} x {}", at, rows, cols,
                       sc_config.num_rings, sc_config.num_sectors));
  }
  Eigen::MatrixXf descriptor(rows, cols);
  for (Eigen::Index i = 0; i < descriptor.size(); ++i) {
    descriptor.data()[i] = r.finite_float("a Scan Context cell", 1.0e4F);
  }
  return scan_context_from_descriptor(std::move(descriptor));
}

// One place's Semantic Scan Context: its class-coded points, then its key
// sectors (as many as the map's loop.ssc.key_sectors); the cells are rebuilt.
SemanticScanContext read_ssc(ByteReader& r, const std::string& at, const SscConfig& ssc_config) {
  SemanticScanContext ssc;
  const std::size_t points = r.count(r.get<std::uint32_t>("SSC point count"), 9, "SSC points", kMaxSscPoints);
  ssc.points.resize(points);
  ssc.codes.resize(points);
  for (std::size_t i = 0; i < points; ++i) {
    const float x = r.finite_float("an SSC point", kMaxFeatureCoordinate);
    const float y = r.finite_float("an SSC point", kMaxFeatureCoordinate);
    ssc.points[i] = {x, y};
    ssc.codes[i] = r.get<std::uint8_t>("an SSC class code");
    if (ssc.codes[i] == 0 || ssc.codes[i] >= kSscNumCodes) {
      r.fail(fmt::format("{}: SSC class code {} (1..{})", at, ssc.codes[i], kSscNumCodes - 1));
    }
  }
  const auto keys = r.get<std::uint32_t>("SSC key sectors");
  if (keys != static_cast<std::uint32_t>(ssc_config.key_sectors)) {
    r.fail(fmt::format("{}: {} SSC key sectors; the map's loop.ssc.key_sectors is {}", at, keys, ssc_config.key_sectors));
  }
  r.count(keys, 12, "SSC key sectors", keys);
  ssc.key_range.resize(keys);
  ssc.key_points.resize(keys);
  for (std::size_t i = 0; i < keys; ++i) {
    ssc.key_range[i] = r.finite_float("an SSC key range", kMaxFeatureCoordinate);
    if (ssc.key_range[i] < 0) r.fail(fmt::format("{}: negative SSC key range", at));
    const float x = r.finite_float("an SSC key point", kMaxFeatureCoordinate);
    const float y = r.finite_float("an SSC key point", kMaxFeatureCoordinate);
    ssc.key_points[i] = {x, y};
  }
  ssc.cells = ssc_cells(ssc.points, ssc.codes, SscAlignment{}, ssc_config);
  return ssc;
}

// One place's semantic graph (node classes and centres) and SGPR embedding.
void read_sgpr(ByteReader& r, const std::string& at, PlaceDescriptor& p) {
  const std::size_t nodes = r.count(r.get<std::uint32_t>("graph node count"), 28, "graph nodes", kMaxGraphNodes);
  p.graph.nodes.resize(nodes);
  p.graph.centers.resize(nodes);
  for (std::size_t i = 0; i < nodes; ++i) {
    const auto c = r.get<std::int32_t>("a node class");
    if (c < 0 || c >= kNumNodeClasses) r.fail(fmt::format("{}: node class {} (0..{})", at, c, kNumNodeClasses - 1));
    p.graph.nodes[i] = c;
    for (int a = 0; a < 3; ++a) p.graph.centers[i][a] = r.finite("a node centre", kMaxGraphCoordinate);
  }
  for (int i = 0; i < kSgprEmbeddingSize; ++i) p.embedding[i] = r.finite_float("an SGPR embedding value", 1.0e6F);
}

}  // namespace

std::vector<PlaceDescriptor> parse_map_places(std::span<const std::byte> bytes, const SaloamConfig& config,
                                              const fs::path& origin) {
  ByteReader r(bytes, origin);
  const std::size_t n = r.count(r.header(MapTable::kPlaces), 4, "place descriptors", kMaxMapKeyframes);
  std::vector<PlaceDescriptor> places(n);
  for (std::size_t k = 0; k < n; ++k) {
    PlaceDescriptor& p = places[k];
    const std::string at = fmt::format("place {}", k);
    const auto flags = r.get<std::uint32_t>("descriptor flags");
    if ((flags & ~kKnownPlaceFlags) != 0) r.fail(fmt::format("{}: unknown descriptor flags {:#x}", at, flags));
    if (flags & kHasScanContext) p.context = read_scan_context(r, at);
    if (flags & kHasSsc) p.ssc = read_ssc(r, at, config.loop.ssc);
    if (flags & kHasSgpr) read_sgpr(r, at, p);
  }
  r.finish();
  return places;
}

std::vector<std::uint64_t> parse_map_digests(std::span<const std::byte> bytes, std::size_t keyframes,
                                             const fs::path& origin) {
  ByteReader r(bytes, origin);
  const std::size_t n = r.count(r.header(MapTable::kDigests), 8, "digests", kMaxMapKeyframes);
  if (n != keyframes) r.fail(fmt::format("{} digests for {} keyframes", n, keyframes));
  std::vector<std::uint64_t> digests(n);
  for (std::uint64_t& d : digests) d = r.get<std::uint64_t>("a digest");
  r.finish();
  return digests;
}

std::uint64_t map_table_max_bytes(std::span<const std::byte> head, MapTable table, const SaloamConfig& config,
                                  const fs::path& origin) {
  ByteReader r(head, origin);
  const std::uint64_t records = r.header(table);
  if (table == MapTable::kFeatures && records == 1 && head.size() >= kHeaderBytes + 16) {
    const std::uint64_t edges = r.get<std::uint64_t>("edge count"), planars = r.get<std::uint64_t>("planar count");
    if (edges > kMaxKeyframeFeatures || planars > kMaxKeyframeFeatures) {
      r.fail(fmt::format("{} edge and {} planar points exceed the limit of {}", edges, planars, kMaxKeyframeFeatures));
    }
    return kHeaderBytes + 16 + (edges + planars) * 13;
  }
  const std::uint64_t per_record = max_map_record_bytes(table, config);
  constexpr std::uint64_t kNoLimit = std::numeric_limits<std::uint64_t>::max();
  return records > (kNoLimit - kHeaderBytes) / per_record ? kNoLimit : kHeaderBytes + records * per_record;
}

std::uint64_t max_map_record_bytes(MapTable table, const SaloamConfig& config) {
  switch (table) {
    case MapTable::kKeyframes: return 8 + 8 + 8 + 96 + 96 + 4;
    case MapTable::kEdges: return 12 + 96 + 21 * 8;
    case MapTable::kDigests: return 8;
    case MapTable::kFeatures: return 16 + 2 * kMaxKeyframeFeatures * 13;
    case MapTable::kPlaces: {
      const ScanContextConfig sc;
      const std::uint64_t context = 8 + 4ull * static_cast<std::uint64_t>(sc.num_rings * sc.num_sectors);
      const std::uint64_t ssc = 4 + 9ull * kMaxSscPoints + 4 + 12ull * static_cast<std::uint64_t>(std::max(0, config.loop.ssc.key_sectors));
      const std::uint64_t sgpr = 4 + 28ull * kMaxGraphNodes + 4ull * kSgprEmbeddingSize;
      return 4 + context + ssc + sgpr;
    }
  }
  return 0;
}

StoredFeatures parse_map_features(std::span<const std::byte> bytes, const fs::path& origin) {
  ByteReader r(bytes, origin);
  if (r.header(MapTable::kFeatures) != 1) r.fail("a feature file holds one record");
  StoredFeatures f;
  const std::uint64_t edges = r.get<std::uint64_t>("edge count"), planars = r.get<std::uint64_t>("planar count");
  if (edges > kMaxKeyframeFeatures || planars > kMaxKeyframeFeatures) {
    r.fail(fmt::format("{} edge and {} planar points exceed the limit of {}", edges, planars, kMaxKeyframeFeatures));
  }
  r.count(edges + planars, 13, "feature points", 2 * kMaxKeyframeFeatures);
  const auto cloud = [&](std::uint64_t n, std::vector<Eigen::Vector3f>& points, std::vector<ClassIndex>& classes) {
    points.resize(n);
    classes.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (int a = 0; a < 3; ++a) points[i][a] = r.finite_float("a feature coordinate", kMaxFeatureCoordinate);
      classes[i] = r.get<ClassIndex>("a feature class");
      if (classes[i] >= kNumClassIndices) r.fail(fmt::format("feature class index {} (0..{})", classes[i], kNumClassIndices - 1));
    }
  };
  cloud(edges, f.edge_points, f.edge_classes);
  cloud(planars, f.planar_points, f.planar_classes);
  r.finish();
  return f;
}

}  // namespace saloam
