#pragma once
// Place recognition of single scans behind one interface: SGPR (the paper's
// scorer: a semantic graph per scan, its pooled embedding kept, pairs scored
// in one batch by the network's head), Scan Context, or a hybrid of both.
// `describe` turns a scan into what is stored per keyframe; `match` scores a
// query against a batch of stored descriptors. Used by loop closure and by
// `saloam place-eval`.

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/place/scan_context.hpp"
#include "saloam/place/semantic_graph.hpp"
#include "saloam/place/sgpr_network.hpp"

namespace saloam {

enum class PlaceDetector { kSgpr, kScanContext, kHybrid };

/// "sgpr", "scancontext" or "hybrid"; ConfigError otherwise.
PlaceDetector parse_place_detector(std::string_view name);
std::string_view place_detector_name(PlaceDetector detector);
[[nodiscard]] inline bool uses_sgpr(PlaceDetector d) { return d != PlaceDetector::kScanContext; }
[[nodiscard]] inline bool uses_scan_context(PlaceDetector d) { return d != PlaceDetector::kSgpr; }

/// What is kept of one scan for place recognition (what a detector does not
/// use stays empty).
struct PlaceDescriptor {
  SemanticGraph graph;  ///< nodes and centres (the paper's "semantic graph map"), SGPR only
  SgprEmbedding embedding = SgprEmbedding::Zero();
  ScanContext context;
};

struct PlaceMatch {
  double score = 0;             ///< the detector's similarity, higher = more alike
  double sgpr_score = 0;        ///< SGPR similarity in (0, 1) (0 when unused)
  double scancontext_score = 0; ///< 1 - Scan Context distance (0 when unused)
  /// Yaw of T_candidate<-query [rad] from Scan Context's best column shift;
  /// nullopt for SGPR alone (its embedding is rotation invariant).
  std::optional<double> yaw;
};

class PlaceRecognizer {
 public:
  /// `network` is required when the detector uses SGPR (std::invalid_argument otherwise).
  PlaceRecognizer(PlaceDetector detector, std::optional<SgprNetwork> network, GraphBuilderConfig graph_config = {},
                  ScanContextConfig context_config = {});

  /// The descriptor of a scan in its sensor frame (SGPR needs labels).
  [[nodiscard]] PlaceDescriptor describe(const LabelledCloud& scan) const;
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
};

}  // namespace saloam
