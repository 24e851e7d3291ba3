// The saved map's readers (maps/map_format.hpp; versions 1 and 2): the first byte picks the
// file (0 map.json, 1 keyframes.bin, 2 edges.bin, 3 places.bin, 4 a
// feature file), the rest is its content. Accepted input must keep the
// format's promises: finite values, orthonormal rotations, edges between
// existing keyframes with positive-definite information, classes and codes
// in range, descriptors of the configured sizes; anything else is an
// InputError naming the file.

#include <cmath>

#include <Eigen/Cholesky>

#include "fuzz_support.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/maps/map_format.hpp"

namespace {

void check_pose(const saloam::Pose& p) {
  SALOAM_FUZZ_CHECK(p.matrix().allFinite());
  SALOAM_FUZZ_CHECK(saloam::orthonormality_error(p.linear()) < 1e-6);
  SALOAM_FUZZ_CHECK(p.linear().determinant() > 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  if (size == 0) return 0;
  const std::uint8_t which = data[0] % 5;
  const std::span<const std::byte> bytes = fuzz::as_bytes(data + 1, size - 1);
  const std::filesystem::path origin = which == 0 ? "/map/map.json" : "/map/table.bin";
  const SaloamConfig config;
  try {
    switch (which) {
      case 0: {
        const MapManifest m = parse_map_manifest(fuzz::as_text(data + 1, size - 1), origin);
        SALOAM_FUZZ_CHECK(m.version >= kMapFormatOldestVersion && m.version <= kMapFormatVersion && m.keyframes > 0 &&
                          m.loop_edges <= m.edges && m.cross_session_loops <= m.loop_edges);
        SALOAM_FUZZ_CHECK(!m.sessions.empty() && m.sessions.front().linked);
        std::uint64_t session_keyframes = 0;
        for (const MapSession& s : m.sessions) session_keyframes += s.keyframes;
        SALOAM_FUZZ_CHECK(session_keyframes == m.keyframes);
        check_pose(m.velo_to_cam);
        (void)parse_place_detector(m.detector);
        if (m.version >= 3) SALOAM_FUZZ_CHECK(m.id.size() == 32 && m.digests.size() == std::size(kMapDigestedFiles));
        break;
      }
      case 1: {
        const auto keyframes = parse_map_keyframes(bytes, origin);
        for (std::size_t k = 0; k < keyframes.size(); ++k) {
          check_pose(keyframes[k].pose);
          check_pose(keyframes[k].odometry_pose);
          SALOAM_FUZZ_CHECK(std::isfinite(keyframes[k].timestamp) && keyframes[k].travelled >= 0);
          if (k == 0) SALOAM_FUZZ_CHECK(keyframes[k].session == 0);
          if (k > 0 && keyframes[k].session == keyframes[k - 1].session) {
            SALOAM_FUZZ_CHECK(keyframes[k].frame > keyframes[k - 1].frame);
          }
          if (k > 0) SALOAM_FUZZ_CHECK(keyframes[k].session - keyframes[k - 1].session <= 1);
        }
        break;
      }
      case 2: {
        constexpr std::size_t kNodes = 16;
        for (const auto& e : parse_map_edges(bytes, kNodes, origin)) {
          SALOAM_FUZZ_CHECK(e.from < kNodes && e.to < kNodes && e.from != e.to);
          check_pose(e.measured);
          SALOAM_FUZZ_CHECK(e.information.allFinite() && e.information.isApprox(e.information.transpose()));
          SALOAM_FUZZ_CHECK(Eigen::LLT<Matrix6d>(e.information).info() == Eigen::Success);
        }
        break;
      }
      case 3: {
        for (const auto& p : parse_map_places(bytes, config, origin)) {
          SALOAM_FUZZ_CHECK(p.context.descriptor.size() == 0 || p.context.descriptor.allFinite());
          SALOAM_FUZZ_CHECK(p.context.ring_key.size() == p.context.descriptor.rows());
          SALOAM_FUZZ_CHECK(p.ssc.points.size() == p.ssc.codes.size());
          for (const auto c : p.ssc.codes) SALOAM_FUZZ_CHECK(c >= 1 && c < kSscNumCodes);
          SALOAM_FUZZ_CHECK(p.ssc.key_range.size() == p.ssc.key_points.size());
          SALOAM_FUZZ_CHECK(p.ssc.key_range.empty() ||
                            p.ssc.cells.size() == static_cast<std::size_t>(config.loop.ssc.rings * config.loop.ssc.sectors));
          SALOAM_FUZZ_CHECK(p.graph.nodes.size() == p.graph.centers.size());
          for (const auto n : p.graph.nodes) SALOAM_FUZZ_CHECK(n >= 0 && n < kNumNodeClasses);
          SALOAM_FUZZ_CHECK(p.embedding.allFinite());
        }
        break;
      }
      default: {
        const StoredFeatures f = parse_map_features(bytes, origin);
        SALOAM_FUZZ_CHECK(f.edge_points.size() == f.edge_classes.size());
        SALOAM_FUZZ_CHECK(f.planar_points.size() == f.planar_classes.size());
        for (const auto& p : f.edge_points) SALOAM_FUZZ_CHECK(p.allFinite());
        for (const auto& p : f.planar_points) SALOAM_FUZZ_CHECK(p.allFinite());
        for (const auto c : f.edge_classes) SALOAM_FUZZ_CHECK(c < kNumClassIndices);
        for (const auto c : f.planar_classes) SALOAM_FUZZ_CHECK(c < kNumClassIndices);
        break;
      }
    }
  } catch (const InputError& e) {
    fuzz::check_names_input(e, origin);
  }
  return 0;
}
