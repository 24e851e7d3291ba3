#pragma once
// Place recognition of single scans behind one interface: SGPR (the paper's
// scorer: a semantic graph per scan, its pooled embedding kept, pairs scored
// in one batch by the network's head), Scan Context, a hybrid of both, or
// Semantic Scan Context (which also returns the relative yaw and x-y offset).
// `describe` turns a scan into what is stored per keyframe; `match` scores a
// query against a batch of stored descriptors. Used by loop closure and by
// `saloam place-eval`.

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"
#include "saloam/place/scan_context.hpp"
#include "saloam/place/semantic_scan_context.hpp"
#include "saloam/place/semantic_graph.hpp"
#include "saloam/place/sgpr_network.hpp"

namespace saloam {

enum class PlaceDetector { kSgpr, kScanContext, kHybrid, kSsc };

/// "sgpr", "scancontext", "hybrid" or "ssc"; ConfigError otherwise.
PlaceDetector parse_place_detector(std::string_view name);
std::string_view place_detector_name(PlaceDetector detector);
[[nodiscard]] inline bool uses_sgpr(PlaceDetector d) { return d == PlaceDetector::kSgpr || d == PlaceDetector::kHybrid; }
[[nodiscard]] inline bool uses_scan_context(PlaceDetector d) {
  return d == PlaceDetector::kScanContext || d == PlaceDetector::kHybrid;
}
[[nodiscard]] inline bool uses_ssc(PlaceDetector d) { return d == PlaceDetector::kSsc; }
/// The detector reads semantic labels (SGPR's graphs, SSC's classes).
[[nodiscard]] inline bool needs_labels(PlaceDetector d) { return uses_sgpr(d) || uses_ssc(d); }

/// What is kept of one scan for place recognition (what a detector does not
/// use stays empty).
struct PlaceDescriptor {
  SemanticGraph graph;  ///< nodes and centres (the paper's "semantic graph map"), SGPR only
  SgprEmbedding embedding = SgprEmbedding::Zero();
  ScanContext context;
  SemanticScanContext ssc;
};

struct PlaceMatch {
  double score = 0;             ///< the detector's similarity, higher = more alike
  double sgpr_score = 0;        ///< SGPR similarity in (0, 1) (0 when unused)
  double scancontext_score = 0; ///< 1 - Scan Context distance (0 when unused)
  double ssc_score = 0;         ///< Semantic Scan Context similarity in [0, 1] (0 when unused)
  /// Yaw of T_candidate<-query [rad] from Scan Context's best column shift
  /// or SSC's alignment; nullopt for SGPR alone (its embedding is rotation
  /// invariant).
  std::optional<double> yaw;
  /// x, y of T_candidate<-query [m] from SSC's alignment (nullopt for the
  /// other detectors, which give no translation).
  std::optional<Eigen::Vector2d> translation;
};

class PlaceRecognizer {
 public:
  /// `network` is required when the detector uses SGPR (std::invalid_argument otherwise).
  PlaceRecognizer(PlaceDetector detector, std::optional<SgprNetwork> network, GraphBuilderConfig graph_config = {},
                  ScanContextConfig context_config = {}, SscConfig ssc_config = {});
  /// The loop closure's recogniser: `loop.detector` with `loop.ssc`
  /// (SGPR's `network` when the detector uses it), as SLAM, localisation
  /// and the joining of sessions describe and match keyframes.
  static PlaceRecognizer from_config(const LoopClosureConfig& loop, std::optional<SgprNetwork> network);

  /// The descriptor of a scan in its sensor frame (SGPR needs labels).
  [[nodiscard]] PlaceDescriptor describe(const LabelledCloud& scan) const;
  /// The SGPR descriptor of an already built graph (e.g. one saved by
  /// `place-eval --save-graphs`); std::logic_error when the detector is not SGPR.
  [[nodiscard]] PlaceDescriptor describe_graph(SemanticGraph graph) const;
  /// Scores of (query, candidate) for every candidate, in order. SGPR
  /// evaluates the query as the first graph, as in place-eval.
  [[nodiscard]] std::vector<PlaceMatch> match(const PlaceDescriptor& query,
                                              std::span<const PlaceDescriptor* const> candidates) const;

  [[nodiscard]] PlaceDetector detector() const { return detector_; }

 private:
  PlaceDetector detector_;
  std::optional<SgprNetwork> network_;
  GraphBuilderConfig graph_config_;
  ScanContextConfig context_config_;
  SscConfig ssc_config_;
};

}  // namespace saloam
