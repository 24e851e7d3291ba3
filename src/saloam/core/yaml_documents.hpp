#pragma once
// What every reader of a YAML file (the configuration, sensor profiles,
// segmenter descriptions, data recipes) needs beyond yaml-cpp: its documents
// read with a bound, and maps whose keys are names given once.

#include <string>
#include <string_view>

#include <yaml-cpp/yaml.h>

namespace saloam {

/// A file that holds one YAML document (a configuration, a sensor profile, a
/// segmenter description, a data recipe).
struct YamlDocument {
  YAML::Node root;      ///< the document; null for a text with none (an empty file)
  std::string problem;  ///< why there is no document, for an error message; empty: `root` is it
};
/// The one document of `text`, or the problem: "not valid YAML (line 3):
/// ..." or "holds 2 YAML documents (separated by '---'); a configuration is
/// one" (`what`: "a configuration"). Empty documents are not counted. The
/// documents are counted before they are loaded, and more than 64 are
/// invalid: yaml-cpp 0.7's LoadAll never ends on some malformed texts (e.g.
/// "&a," alone: the parser hands out the same empty document again and
/// again, and LoadAll keeps them until memory runs out).
YamlDocument load_yaml_document(std::string_view text, std::string_view what);

/// What is wrong with the keys of the map `node`, as a phrase for an error
/// message: "'odometry.k' is given twice (lines 3 and 9): give each key
/// once" or "line 4: a key in 'odometry' that is not a name (a list or a
/// map)" (`section` is the map's dotted name, empty at the top). Empty when
/// every key is a name given once, and for a node that is not a map.
/// yaml-cpp accepts a list or a map as a key, which names nothing here, and
/// keeps both entries of a repeated key: which one a lookup finds is not what
/// the user meant to say.
std::string key_problem(const YAML::Node& node, const std::string& section = "");

}  // namespace saloam
