#include "saloam/place/place_recognizer.hpp"

#include <numbers>
#include <stdexcept>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace saloam {

PlaceDetector parse_place_detector(std::string_view name) {
  if (name == "sgpr") return PlaceDetector::kSgpr;
  if (name == "scancontext") return PlaceDetector::kScanContext;
  if (name == "hybrid") return PlaceDetector::kHybrid;
  if (name == "ssc") return PlaceDetector::kSsc;
  throw ConfigError(fmt::format("unknown place-recognition detector '{}': use sgpr, scancontext, hybrid or ssc", name));
}

std::string_view place_detector_name(PlaceDetector detector) {
  switch (detector) {
    case PlaceDetector::kSgpr: return "sgpr";
    case PlaceDetector::kScanContext: return "scancontext";
    case PlaceDetector::kHybrid: return "hybrid";
    case PlaceDetector::kSsc: return "ssc";
  }
  return "?";
}

PlaceRecognizer PlaceRecognizer::from_config(const LoopClosureConfig& loop, std::optional<SgprNetwork> network) {
  return PlaceRecognizer(parse_place_detector(loop.detector), std::move(network), GraphBuilderConfig{},
                         ScanContextConfig{}, loop.ssc);
}

PlaceRecognizer::PlaceRecognizer(PlaceDetector detector, std::optional<SgprNetwork> network,
                                 GraphBuilderConfig graph_config, ScanContextConfig context_config,
                                 SscConfig ssc_config)
    : detector_(detector),
      network_(std::move(network)),
      graph_config_(graph_config),
      context_config_(context_config),
      ssc_config_(ssc_config) {
  if (uses_sgpr(detector_) && !network_) {
    throw std::invalid_argument("PlaceRecognizer: the SGPR detector needs the network's weights");
  }
}

PlaceDescriptor PlaceRecognizer::describe(const LabelledCloud& scan) const {
  PlaceDescriptor d;
  if (uses_sgpr(detector_)) {
    d.graph = build_semantic_graph(scan, graph_config_);
    d.embedding = network_->embed(d.graph);
  }
  if (uses_scan_context(detector_)) d.context = make_scan_context(scan.points, context_config_);
  if (uses_ssc(detector_)) d.ssc = make_semantic_scan_context(scan, ssc_config_);
  return d;
}

PlaceDescriptor PlaceRecognizer::describe_graph(SemanticGraph graph) const {
  if (!uses_sgpr(detector_)) throw std::logic_error("PlaceRecognizer::describe_graph: the detector does not use SGPR");
  PlaceDescriptor d;
  d.graph = std::move(graph);
  d.embedding = network_->embed(d.graph);
  return d;
}

std::vector<PlaceMatch> PlaceRecognizer::match(const PlaceDescriptor& query,
                                               std::span<const PlaceDescriptor* const> candidates) const {
  std::vector<PlaceMatch> matches(candidates.size());
  if (uses_sgpr(detector_)) {
    std::vector<SgprEmbedding> embeddings;
    embeddings.reserve(candidates.size());
    for (const auto* c : candidates) embeddings.push_back(c->embedding);
    const std::vector<double> scores = network_->score_batch(query.embedding, embeddings);
    for (std::size_t k = 0; k < candidates.size(); ++k) matches[k].sgpr_score = scores[k];
  }
  if (uses_scan_context(detector_)) {
    const double sector = 2.0 * std::numbers::pi / context_config_.num_sectors;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      const ScanContextMatch m = scan_context_distance(query.context, candidates[k]->context);
      matches[k].scancontext_score = 1.0 - m.distance;
      // The candidate's column d = c + shift sees what the query's column c
      // sees: directions in the candidate frame are the query's turned by
      // +shift sectors about z.
      double yaw = m.shift * sector;
      if (yaw > std::numbers::pi) yaw -= 2.0 * std::numbers::pi;
      matches[k].yaw = yaw;
    }
  }
  if (uses_ssc(detector_)) {
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      const SscMatch m = match_semantic_scan_contexts(query.ssc, candidates[k]->ssc, ssc_config_);
      matches[k].ssc_score = m.score;
      // SSC aligns the candidate onto the query (T_query<-candidate); the
      // match reports T_candidate<-query.
      const Eigen::Rotation2Dd inverse_rotation(-m.alignment.yaw);
      matches[k].yaw = -m.alignment.yaw;
      matches[k].translation = -(inverse_rotation * m.alignment.translation);
    }
  }
  for (auto& m : matches) {
    switch (detector_) {
      case PlaceDetector::kSgpr: m.score = m.sgpr_score; break;
      case PlaceDetector::kScanContext: m.score = m.scancontext_score; break;
      case PlaceDetector::kHybrid: m.score = 0.5 * (m.sgpr_score + m.scancontext_score); break;
      case PlaceDetector::kSsc: m.score = m.ssc_score; break;
    }
  }
  return matches;
}

}  // namespace saloam
