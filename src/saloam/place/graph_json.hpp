#pragma once
// Semantic graphs as JSON in SGPR's own format, so graphs can be exchanged
// with the Python original:
//   {"nodes": [label, ...], "centers": [[x, y, z], ...],
//    "edges": [[i, j], ...], "weights": [w, ...], "pose": [12 numbers]}
// `edges`, `weights` and `pose` are optional when reading (SGPR's published
// graphs carry only nodes, centers and pose).

#include <filesystem>
#include <istream>
#include <string>

#include <nlohmann/json.hpp>

#include "saloam/place/semantic_graph.hpp"

namespace saloam {

/// An edge weight (1 - d / edge_distance) beyond this in magnitude is not one.
inline constexpr double kMaxGraphEdgeWeight = 1.0e3;

nlohmann::json graph_to_json(const SemanticGraph& graph);
/// Throws InputError(source, ...) for missing fields, wrong types, classes
/// outside 0..11, non-finite numbers, centres beyond kMaxGraphCoordinate (semantic_graph.hpp),
/// edge weights beyond kMaxGraphEdgeWeight, mismatched lengths or bad edge
/// indices.
SemanticGraph graph_from_json(const nlohmann::json& json, const std::filesystem::path& source);

/// Writes the graph as one-line JSON (doubles printed round-trip exact).
void write_graph_json(const std::filesystem::path& file, const SemanticGraph& graph);
/// Reads a graph file; InputError when missing, not JSON or malformed.
SemanticGraph read_graph_json(const std::filesystem::path& file);
/// Parses a graph from an open stream (`source` names it in errors); the same
/// InputErrors as read_graph_json.
SemanticGraph parse_graph_json(std::istream& in, const std::filesystem::path& source);

}  // namespace saloam
