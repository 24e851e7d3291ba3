#include "saloam/place/graph_json.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <limits>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"

namespace saloam {
namespace {
// A scan's graph is a few kB; a file this large is not one.
constexpr std::size_t kMaxGraphBytes = std::size_t{64} << 20;
}  // namespace

nlohmann::json graph_to_json(const SemanticGraph& graph) {
  nlohmann::json j;
  j["nodes"] = graph.nodes;
  auto centers = nlohmann::json::array();
  for (const auto& c : graph.centers) centers.push_back({c.x(), c.y(), c.z()});
  j["centers"] = std::move(centers);
  auto edges = nlohmann::json::array();
  for (const auto& e : graph.edges) edges.push_back({e[0], e[1]});
  j["edges"] = std::move(edges);
  j["weights"] = graph.weights;
  if (graph.pose) j["pose"] = *graph.pose;
  return j;
}

namespace {
// Reads a graph's JSON field by field; every problem is an InputError naming
// the source and the field.
class GraphJsonReader {
 public:
  explicit GraphJsonReader(const std::filesystem::path& source) : source_(source) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(source_, "semantic graph: " + problem);
  }

  void read_nodes(const nlohmann::json& nodes, SemanticGraph& graph) const {
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const auto& v = nodes[i];
      if (!v.is_number_integer()) fail("nodes[" + std::to_string(i) + "] is not an integer");
      const std::int64_t label = integer(v);
      if (label < 0 || label >= kNumNodeClasses)
        fail("nodes[" + std::to_string(i) + "] = " + v.dump() + " is not a node class 0..11");
      graph.nodes.push_back(static_cast<int>(label));
    }
  }

  void read_centers(const nlohmann::json& centers, SemanticGraph& graph) const {
    for (std::size_t i = 0; i < centers.size(); ++i) {
      const auto& c = centers[i];
      const std::string what = "centers[" + std::to_string(i) + "]";
      if (!c.is_array() || c.size() != 3) fail(what + " is not [x, y, z]");
      graph.centers.emplace_back(number(c[0], what, kMaxGraphCoordinate), number(c[1], what, kMaxGraphCoordinate),
                                 number(c[2], what, kMaxGraphCoordinate));
    }
  }

  void read_edges(const nlohmann::json& edges, SemanticGraph& graph) const {
    if (!edges.is_array()) fail("'edges' is not an array");
    for (std::size_t i = 0; i < edges.size(); ++i) {
      const auto& e = edges[i];
      const std::string what = "edges[" + std::to_string(i) + "]";
      if (!e.is_array() || e.size() != 2 || !e[0].is_number_integer() || !e[1].is_number_integer())
        fail(what + " is not a pair of node indices");
      const std::int64_t a = integer(e[0]), b = integer(e[1]);
      const auto n = static_cast<std::int64_t>(graph.nodes.size());
      if (a < 0 || b < 0 || a >= n || b >= n) fail(what + " refers to a node that does not exist");
      graph.edges.push_back({static_cast<int>(a), static_cast<int>(b)});
    }
  }

  void read_weights(const nlohmann::json& weights, SemanticGraph& graph) const {
    if (!weights.is_array()) fail("'weights' is not an array");
    for (std::size_t i = 0; i < weights.size(); ++i)
      graph.weights.push_back(number(weights[i], "weights[" + std::to_string(i) + "]", kMaxGraphEdgeWeight));
  }

  std::array<double, 12> read_pose(const nlohmann::json& p) const {
    if (!p.is_array() || p.size() != 12) fail("'pose' is not a list of 12 numbers");
    std::array<double, 12> pose{};
    for (std::size_t i = 0; i < 12; ++i) pose[i] = number(p[i], "pose[" + std::to_string(i) + "]");
    return pose;
  }

 private:
  // A finite number, within +-limit when limit > 0.
  double number(const nlohmann::json& v, const std::string& what, double limit = 0.0) const {
    if (!v.is_number()) fail(what + " is not a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(what + " is not finite");
    if (limit > 0.0 && std::abs(d) > limit) fail(fmt::format("{} = {:g} is beyond +-{:g}", what, d, limit));
    return d;
  }

  // An integer's value as it is in the file: get<int>() would wrap a large
  // one (4294967299 would read as class 3), so compare in 64 bits.
  static std::int64_t integer(const nlohmann::json& v) {
    if (v.is_number_unsigned()) {
      const auto u = v.get<std::uint64_t>();
      constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
      return static_cast<std::int64_t>(u > kMax ? kMax : u);
    }
    return v.get<std::int64_t>();
  }

  const std::filesystem::path& source_;
};
}  // namespace

SemanticGraph graph_from_json(const nlohmann::json& json, const std::filesystem::path& source) {
  const GraphJsonReader reader(source);
  if (!json.is_object()) reader.fail("top level is not a JSON object");
  if (!json.contains("nodes") || !json["nodes"].is_array()) reader.fail("missing array 'nodes'");
  if (!json.contains("centers") || !json["centers"].is_array()) reader.fail("missing array 'centers'");
  SemanticGraph graph;
  reader.read_nodes(json["nodes"], graph);
  reader.read_centers(json["centers"], graph);
  if (graph.centers.size() != graph.nodes.size())
    reader.fail(std::to_string(graph.nodes.size()) + " nodes but " + std::to_string(graph.centers.size()) +
                " centers");
  if (json.contains("edges")) reader.read_edges(json["edges"], graph);
  if (json.contains("weights")) reader.read_weights(json["weights"], graph);
  if (graph.weights.size() != graph.edges.size())
    reader.fail(std::to_string(graph.edges.size()) + " edges but " + std::to_string(graph.weights.size()) +
                " weights");
  if (json.contains("pose") && !json["pose"].is_null()) graph.pose = reader.read_pose(json["pose"]);
  return graph;
}

void write_graph_json(const std::filesystem::path& file, const SemanticGraph& graph) {
  write_file_atomically(file, graph_to_json(graph).dump() + '\n');
}

SemanticGraph read_graph_json(const std::filesystem::path& file) {
  std::istringstream in(read_file(file, kMaxGraphBytes, "graph file"));
  return parse_graph_json(in, file);
}

SemanticGraph parse_graph_json(std::istream& in, const std::filesystem::path& source) {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(source, std::string("not valid JSON: ") + e.what());
  }
  return graph_from_json(json, source);
}

}  // namespace saloam
