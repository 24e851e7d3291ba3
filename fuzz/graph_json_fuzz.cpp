// Semantic graphs in SGPR's JSON format (parse_graph_json).

#include <cmath>
#include <sstream>

#include "fuzz_support.hpp"
#include "saloam/place/graph_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  const std::filesystem::path file = "graph.json";
  const std::string text = fuzz::as_text(data, size);
  std::istringstream in(text);
  try {
    const SemanticGraph graph = parse_graph_json(in, file);
    SALOAM_FUZZ_CHECK(graph.centers.size() == graph.nodes.size());
    SALOAM_FUZZ_CHECK(graph.weights.size() == graph.edges.size());
    const int n = static_cast<int>(graph.nodes.size());
    for (const int label : graph.nodes) SALOAM_FUZZ_CHECK(label >= 0 && label < kNumNodeClasses);
    for (const auto& c : graph.centers) SALOAM_FUZZ_CHECK(c.allFinite() && c.cwiseAbs().maxCoeff() <= kMaxGraphCoordinate);
    for (const auto& e : graph.edges) SALOAM_FUZZ_CHECK(e[0] >= 0 && e[1] >= 0 && e[0] < n && e[1] < n);
    for (const double w : graph.weights) SALOAM_FUZZ_CHECK(std::isfinite(w) && std::abs(w) <= kMaxGraphEdgeWeight);
    if (graph.pose)
      for (const double v : *graph.pose) SALOAM_FUZZ_CHECK(std::isfinite(v));
    // Every index and class is the number in the file, not a wrapped one.
    const auto json = nlohmann::json::parse(text);
    for (std::size_t i = 0; i < graph.nodes.size(); ++i) SALOAM_FUZZ_CHECK(json["nodes"][i] == graph.nodes[i]);
    for (std::size_t i = 0; i < graph.edges.size(); ++i)
      SALOAM_FUZZ_CHECK(json["edges"][i][0] == graph.edges[i][0] && json["edges"][i][1] == graph.edges[i][1]);
    // What was read is written and read back the same.
    std::istringstream again(graph_to_json(graph).dump());
    const SemanticGraph round_trip = parse_graph_json(again, file);
    SALOAM_FUZZ_CHECK(round_trip.nodes == graph.nodes && round_trip.centers == graph.centers &&
                      round_trip.edges == graph.edges && round_trip.weights == graph.weights &&
                      round_trip.pose == graph.pose);
  } catch (const InputError& e) {
    fuzz::check_names_input(e, file);
  }
  return 0;
}
