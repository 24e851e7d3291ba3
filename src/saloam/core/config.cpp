#include "saloam/core/config.hpp"

#include <fstream>
#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>
#include <type_traits>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "saloam/core/error.hpp"
#include "saloam/core/semantic_classes.hpp"

namespace saloam {

double class_value(const ClassValueMap& map, std::uint16_t raw_id, double fallback) {
  if (const auto it = map.find(std::string(class_name(static_class(raw_id)))); it != map.end()) {
    return it->second;
  }
  if (const auto it = map.find("default"); it != map.end()) return it->second;
  return fallback;
}

namespace {

struct Field {
  std::string key;  // "section.name"
  std::string doc;
  std::function<void(const YAML::Node&, const std::string& origin)> set;
  std::function<YAML::Node()> get;
};

template <class T>
void assign(T& member, const YAML::Node& node, const std::string& key, const std::string& origin) {
  if constexpr (std::is_same_v<T, ClassValueMap>) {
    if (!node.IsMap()) {
      throw ConfigError(fmt::format("{}: '{}' must be a map of class name to number", origin, key));
    }
    for (const auto& entry : node) {
      const auto name = entry.first.as<std::string>();
      if (name != "default" && !semantic_class_id(name)) {
        throw ConfigError(fmt::format("{}: '{}' names unknown class '{}'", origin, key, name));
      }
      assign(member[name], entry.second, key + "." + name, origin);
    }
  } else {
    if (!node.IsScalar()) {
      throw ConfigError(fmt::format("{}: '{}' must be a single value", origin, key));
    }
    try {
      member = node.as<T>();
    } catch (const YAML::Exception&) {
      throw ConfigError(fmt::format("{}: '{}' has value '{}' of the wrong type", origin, key,
                                    node.Scalar()));
    }
  }
}

template <class T>
YAML::Node to_node(const T& value) {
  YAML::Node n;
  if constexpr (std::is_same_v<T, ClassValueMap>) {
    for (const auto& [name, v] : value) n[name] = fmt::format("{}", v);
  } else if constexpr (std::is_floating_point_v<T>) {
    // Shortest text that reads back exactly; YAML spells infinity ".inf".
    n = std::isinf(value) ? std::string(value > 0 ? ".inf" : "-.inf") : fmt::format("{}", value);
  } else {
    n = value;
  }
  return n;
}

std::vector<Field> collect_fields(SaloamConfig& config) {
  std::vector<Field> fields;
  visit_sections(config, [&](std::string_view section, auto& s) {
    visit_fields(s, [&](std::string_view name, auto& member, std::string_view doc) {
      const std::string key = fmt::format("{}.{}", section, name);
      fields.push_back(Field{
          key, std::string(doc),
          [&member, key](const YAML::Node& n, const std::string& origin) { assign(member, n, key, origin); },
          [&member] { return to_node(member); }});
    });
  });
  return fields;
}

std::vector<std::string> section_names(SaloamConfig& config) {
  std::vector<std::string> names;
  visit_sections(config, [&](std::string_view section, auto&) { names.emplace_back(section); });
  return names;
}

void apply_node(SaloamConfig& config, const YAML::Node& node, const std::string& prefix,
                const std::string& origin, const std::vector<Field>& fields) {
  if (!node.IsMap()) {
    throw ConfigError(fmt::format("{}: '{}' must be a map", origin, prefix.empty() ? "<root>" : prefix));
  }
  const auto sections = section_names(config);
  for (const auto& entry : node) {
    const auto name = entry.first.as<std::string>();
    const std::string key = prefix.empty() ? name : prefix + "." + name;
    const auto field = std::find_if(fields.begin(), fields.end(), [&](const Field& f) { return f.key == key; });
    if (field != fields.end()) {
      field->set(entry.second, origin);
    } else if (std::find(sections.begin(), sections.end(), key) != sections.end()) {
      apply_node(config, entry.second, key, origin, fields);
    } else {
      throw ConfigError(fmt::format("{}: unknown configuration key '{}'", origin, key));
    }
  }
}

}  // namespace

void apply_config_yaml(SaloamConfig& config, std::string_view yaml_text, std::string_view origin) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml_text));
  } catch (const YAML::Exception& e) {
    throw ConfigError(fmt::format("{}: invalid YAML: {}", origin, e.what()));
  }
  if (root.IsNull()) return;  // empty file: defaults
  apply_node(config, root, "", std::string(origin), collect_fields(config));
}

SaloamConfig load_config(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open configuration file");
  std::stringstream text;
  text << in.rdbuf();
  SaloamConfig config;
  apply_config_yaml(config, text.str(), path.string());
  return config;
}

void apply_config_override(SaloamConfig& config, std::string_view assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string_view::npos || eq == 0) {
    throw ConfigError(fmt::format("--set '{}': expected key=value", assignment));
  }
  std::string key(assignment.substr(0, eq));
  const std::string value(assignment.substr(eq + 1));
  const std::string origin = fmt::format("--set {}", assignment);
  const auto fields = collect_fields(config);

  // A bare field name ("alpha") resolves when exactly one section has it.
  if (key.find('.') == std::string::npos) {
    std::vector<std::string> matches;
    for (const auto& f : fields) {
      if (f.key.size() > key.size() && f.key.ends_with("." + key)) matches.push_back(f.key);
    }
    if (matches.size() > 1) {
      throw ConfigError(fmt::format("{}: '{}' is ambiguous ({})", origin, key, fmt::join(matches, ", ")));
    }
    if (matches.size() == 1) key = matches.front();
  }

  YAML::Node parsed;
  try {
    parsed = YAML::Load(value);
  } catch (const YAML::Exception& e) {
    throw ConfigError(fmt::format("{}: cannot parse value: {}", origin, e.what()));
  }
  for (const auto& f : fields) {
    if (f.key == key) {
      f.set(parsed, origin);
      return;
    }
    // "section.map_field.class=value": one entry of a per-class map.
    if (key.starts_with(f.key + ".") && f.get().IsMap()) {
      YAML::Node entry;
      entry[key.substr(f.key.size() + 1)] = parsed;
      f.set(entry, origin);
      return;
    }
  }
  throw ConfigError(fmt::format("{}: unknown configuration key '{}'", origin, key));
}

std::string config_to_yaml(const SaloamConfig& config_in) {
  SaloamConfig config = config_in;  // the visitors need mutable access
  YAML::Emitter out;
  out << YAML::BeginMap;
  const auto fields = collect_fields(config);
  std::string open_section;
  // Emit nested maps following the dotted keys (sections are visited in order).
  std::function<void(const std::string&)> emit_section = [&](const std::string& section) {
    for (const auto& f : fields) {
      const auto dot = f.key.rfind('.');
      if (f.key.substr(0, dot) != section) continue;
      out << YAML::Key << f.key.substr(dot + 1) << YAML::Value << f.get() << YAML::Comment(f.doc);
    }
    for (const auto& child : section_names(config)) {
      if (child.starts_with(section + ".") && child.find('.', section.size() + 1) == std::string::npos) {
        out << YAML::Key << child.substr(section.size() + 1) << YAML::Value << YAML::BeginMap;
        emit_section(child);
        out << YAML::EndMap;
      }
    }
  };
  for (const auto& section : section_names(config)) {
    if (section.find('.') != std::string::npos) continue;
    out << YAML::Key << section << YAML::Value << YAML::BeginMap;
    emit_section(section);
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace saloam
