#pragma once
// The documents of a YAML text, for the readers of YAML files (the
// configuration, sensor profiles). yaml-cpp 0.7's LoadAll never ends on some
// malformed texts (e.g. "&a," alone: the parser hands out the same empty
// document again and again, and LoadAll keeps them until memory runs out),
// so the documents are counted first, at most kMaxYamlDocuments.

#include <cstddef>
#include <string_view>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace saloam {

inline constexpr std::size_t kMaxYamlDocuments = 64;

/// The documents of `text` that are not empty (null), in order. Throws
/// YAML::Exception for invalid YAML and for more than kMaxYamlDocuments
/// documents.
std::vector<YAML::Node> load_yaml_documents(std::string_view text);

}  // namespace saloam
