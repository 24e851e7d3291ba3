#include "saloam/core/yaml_documents.hpp"

#include <cstddef>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

namespace saloam {
namespace {

/// Parser events thrown away: only whether a document ends is of interest.
class Discard : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

constexpr std::size_t kMaxYamlDocuments = 64;

// The documents of `text` that are not empty (null), in order; YAML::Exception
// for invalid YAML and for more than kMaxYamlDocuments documents, counted
// before LoadAll (load_yaml_document says why).
std::vector<YAML::Node> load_yaml_documents(std::string_view text) {
  const std::string copy(text);
  {
    std::istringstream in(copy);
    YAML::Parser parser(in);
    Discard discard;
    std::size_t documents = 0;
    while (parser.HandleNextDocument(discard)) {
      if (++documents > kMaxYamlDocuments) {
        throw YAML::Exception(YAML::Mark::null_mark(), "more than 64 YAML documents");
      }
    }
  }
  std::vector<YAML::Node> documents = YAML::LoadAll(copy);
  std::erase_if(documents, [](const YAML::Node& document) { return document.IsNull(); });
  return documents;
}

}  // namespace

YamlDocument load_yaml_document(std::string_view text, std::string_view what) {
  YamlDocument document;
  std::vector<YAML::Node> documents;
  try {
    documents = load_yaml_documents(text);
  } catch (const YAML::Exception& e) {
    const std::string line = e.mark.is_null() ? "" : fmt::format(" (line {})", e.mark.line + 1);
    document.problem = fmt::format("not valid YAML{}: {}", line, e.msg.substr(0, 200));
    return document;
  }
  if (documents.size() > 1) {
    document.problem =
        fmt::format("holds {} YAML documents (separated by '---'); {} is one", documents.size(), what);
  } else if (!documents.empty()) {
    document.root = documents.front();
  }
  return document;
}

std::string key_problem(const YAML::Node& node, const std::string& section) {
  if (!node.IsMap()) return {};
  std::map<std::string, int> first_line;
  for (const auto& entry : node) {
    const int line = entry.first.Mark().line + 1;
    if (!entry.first.IsScalar()) {
      return fmt::format("line {}: a key {}that is not a name (a list or a map)", line,
                         section.empty() ? "" : "in '" + section + "' ");
    }
    const std::string& name = entry.first.Scalar();
    if (const auto [it, inserted] = first_line.emplace(name, line); !inserted) {
      return fmt::format("'{}' is given twice (lines {} and {}): give each key once",
                         section.empty() ? name : section + "." + name, it->second, line);
    }
  }
  return {};
}

}  // namespace saloam
