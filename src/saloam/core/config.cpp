#include "saloam/core/config.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <type_traits>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "saloam/core/yaml_documents.hpp"

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
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
  std::string range;  // the valid values as text, e.g. "> 0"; empty: any
  std::function<void(const YAML::Node&, const std::string& origin)> set;
  std::function<YAML::Node()> get;
  std::function<void(const std::string& origin)> check;  // throws ConfigError when out of range
};

// A number as YAML writes it: shortest exact text, infinity as ".inf".
std::string number_text(double x) {
  if (std::isinf(x)) return x > 0 ? ".inf" : "-.inf";
  return fmt::format("{}", x);
}

bool admits(const Range& r, double x) { return x >= r.lo && x <= r.hi; }  // false for NaN
bool admits(const AtLeast& r, double x) { return std::isfinite(x) && x >= r.lo; }
bool admits(const Above& r, double x) { return std::isfinite(x) && x > r.lo; }
template <class T, class V>
bool admits(const OneOf<T>& r, const V& x) {
  return std::find(r.values.begin(), r.values.end(), x) != r.values.end();
}
template <class V>
bool admits(const Any&, const V&) {
  return true;
}

std::string describe(const Range& r) { return fmt::format("[{}, {}]", number_text(r.lo), number_text(r.hi)); }
std::string describe(const AtLeast& r) { return ">= " + number_text(r.lo); }
std::string describe(const Above& r) { return "> " + number_text(r.lo); }
template <class T>
std::string describe(const OneOf<T>& r) {
  return fmt::format("one of {}", fmt::join(r.values, ", "));
}
std::string describe(const Any&) { return ""; }

template <class T>
std::string value_text(const T& value) {
  if constexpr (std::is_same_v<T, std::string>) {
    return fmt::format("'{}'", value);
  } else if constexpr (std::is_floating_point_v<T>) {
    return number_text(value);
  } else {
    return fmt::format("{}", value);
  }
}

// Throws when `value` of field `key` is outside `range`; NaN never passes.
template <class T, class R>
void check_value(const T& value, const R& range, const std::string& key, const std::string& origin) {
  if constexpr (std::is_floating_point_v<T>) {
    if (std::isnan(value)) throw ConfigError(fmt::format("{}: '{}' is NaN (valid: {})", origin, key, describe(range)));
  }
  if (!admits(range, value)) {
    throw ConfigError(
        fmt::format("{}: '{}' = {} is not allowed (valid: {})", origin, key, value_text(value), describe(range)));
  }
}

template <class T, class R>
void check_member(const T& member, const R& range, const std::string& key, const std::string& origin) {
  if constexpr (std::is_same_v<T, ClassValueMap>) {
    for (const auto& [name, value] : member) check_value(value, range, key + "." + name, origin);
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    for (std::size_t i = 0; i < member.size(); ++i) {
      if (std::isnan(member[i]) || !admits(range, member[i])) {
        throw ConfigError(fmt::format("{}: '{}' has {} at [{}], not allowed (valid: {})", origin, key,
                                      number_text(member[i]), i, describe(range)));
      }
    }
  } else {
    check_value(member, range, key, origin);
  }
}

/// ConfigError when a key of the map `node` is not a name or is given twice
/// (key_problem).
void check_keys(const YAML::Node& node, const std::string& section, const std::string& origin) {
  if (const auto problem = key_problem(node, section); !problem.empty()) {
    throw ConfigError(fmt::format("{}: {}", origin, problem));
  }
}

template <class T>
void assign(T& member, const YAML::Node& node, const std::string& key, const std::string& origin) {
  if constexpr (std::is_same_v<T, ClassValueMap>) {
    if (!node.IsMap()) {
      throw ConfigError(fmt::format("{}: '{}' must be a map of class name to number", origin, key));
    }
    check_keys(node, key, origin);
    for (const auto& entry : node) {
      const auto name = entry.first.Scalar();  // a name: check_keys
      if (name != "default" && !semantic_class_id(name)) {
        throw ConfigError(fmt::format("{}: '{}' names unknown class '{}'", origin, key, name));
      }
      assign(member[name], entry.second, key + "." + name, origin);
    }
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    if (!node.IsSequence()) throw ConfigError(fmt::format("{}: '{}' must be a list of numbers, e.g. [1.5, -2]", origin, key));
    std::vector<double> values(node.size());
    for (std::size_t i = 0; i < node.size(); ++i) assign(values[i], node[i], fmt::format("{}[{}]", key, i), origin);
    member = std::move(values);
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
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    n = YAML::Node(YAML::NodeType::Sequence);
    for (const double v : value) n.push_back(number_text(v));
    n.SetStyle(YAML::EmitterStyle::Flow);
  } else if constexpr (std::is_floating_point_v<T>) {
    n = number_text(value);
  } else {
    n = value;
  }
  return n;
}

template <class T, class R>
Field field_of(const std::string& key, std::string_view doc, T& member, const R& range) {
  return Field{key,
               std::string(doc),
               describe(range),
               [&member, key](const YAML::Node& n, const std::string& origin) { assign(member, n, key, origin); },
               [&member] { return to_node(member); },
               [&member, range, key](const std::string& origin) { check_member(member, range, key, origin); }};
}

template <class T, class R>
Field make_field(const std::string& key, std::string_view doc, T& member, const R& range) {
  static_assert(!std::is_same_v<T, bool>, "a bool field takes no range");
  return field_of(key, doc, member, range);
}
// Only a bool leaves out its range (a field of another type without one does not compile).
Field make_field(const std::string& key, std::string_view doc, bool& member) {
  return field_of(key, doc, member, Any{});
}

std::vector<Field> collect_fields(SaloamConfig& config) {
  std::vector<Field> fields;
  visit_sections(config, [&](std::string_view section, auto& s) {
    visit_fields(s, [&](std::string_view name, auto& member, std::string_view doc, const auto&... range) {
      fields.push_back(make_field(fmt::format("{}.{}", section, name), doc, member, range...));
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
  check_keys(node, prefix, origin);
  const auto sections = section_names(config);
  for (const auto& entry : node) {
    const auto name = entry.first.Scalar();  // a name: check_keys
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

// Pairs of fields whose valid values depend on each other.
void check_consistency(const SaloamConfig& config, const std::string& origin) {
  const FeatureConfig& f = config.odometry.features;
  if (!(f.min_range < f.max_range)) {
    throw ConfigError(fmt::format("{}: 'odometry.features.min_range' = {} must be less than "
                                  "'odometry.features.max_range' = {}",
                                  origin, number_text(f.min_range), number_text(f.max_range)));
  }
  if (!(config.loop.delta_min <= config.loop.delta_max)) {
    throw ConfigError(fmt::format("{}: 'loop.delta_min' = {} must not exceed 'loop.delta_max' = {}", origin,
                                  number_text(config.loop.delta_min), number_text(config.loop.delta_max)));
  }
  if (!f.beam_elevations_deg.empty() && f.num_beams != 0 &&
      f.num_beams != static_cast<int>(f.beam_elevations_deg.size())) {
    throw ConfigError(fmt::format("{}: 'odometry.features.num_beams' = {} but 'odometry.features.beam_elevations_deg' "
                                  "lists {} beams (num_beams 0 takes the list's)",
                                  origin, f.num_beams, f.beam_elevations_deg.size()));
  }
  if (!(f.pose_time_in_sweep <= f.sweep_duration)) {
    throw ConfigError(fmt::format("{}: 'odometry.features.pose_time_in_sweep' = {} must lie within the sweep, "
                                  "[0, 'odometry.features.sweep_duration' = {}]",
                                  origin, number_text(f.pose_time_in_sweep), number_text(f.sweep_duration)));
  }
  const std::size_t mount_values = config.odometry.gravity.mount_rpy_deg.size();
  if (mount_values != 0 && mount_values != 3) {
    throw ConfigError(fmt::format("{}: 'odometry.gravity.mount_rpy_deg' has {} values: give roll, pitch and yaw [deg] "
                                  "(3 values), or [] for no mount",
                                  origin, mount_values));
  }
  const SscConfig& ssc = config.loop.ssc;
  if (!(ssc.inner_radius < ssc.outer_radius)) {
    throw ConfigError(fmt::format("{}: 'loop.ssc.inner_radius' = {} must be less than 'loop.ssc.outer_radius' = {}",
                                  origin, number_text(ssc.inner_radius), number_text(ssc.outer_radius)));
  }
}

// The full key of a bare field name ("alpha") when exactly one section has it; else `key` as given.
std::string resolve_short_key(const std::vector<Field>& fields, const std::string& key, const std::string& origin) {
  if (key.find('.') != std::string::npos) return key;
  std::vector<std::string> matches;
  for (const auto& f : fields) {
    if (f.key.size() > key.size() && f.key.ends_with("." + key)) matches.push_back(f.key);
  }
  if (matches.size() > 1) {
    throw ConfigError(fmt::format("{}: '{}' is ambiguous ({})", origin, key, fmt::join(matches, ", ")));
  }
  return matches.size() == 1 ? matches.front() : key;
}

// Sets the field `key`, or one entry of a per-class map ("section.map_field.class").
void set_by_key(const std::vector<Field>& fields, const std::string& key, const YAML::Node& value,
                const std::string& origin) {
  for (const auto& f : fields) {
    if (f.key == key) {
      f.set(value, origin);
      return;
    }
    if (key.starts_with(f.key + ".") && f.get().IsMap()) {
      YAML::Node entry;
      entry[key.substr(f.key.size() + 1)] = value;
      f.set(entry, origin);
      return;
    }
  }
  throw ConfigError(fmt::format("{}: unknown configuration key '{}'", origin, key));
}

// A field's doc followed by its valid values, e.g. "N_m: frames in the local map [>= 1]".
std::string doc_with_range(const Field& f) {
  if (f.range.empty()) return f.doc;
  return f.doc + " " + (f.range.starts_with('[') ? f.range : "[" + f.range + "]");
}

}  // namespace

void validate_config(const SaloamConfig& config_in, std::string_view origin_in) {
  SaloamConfig config = config_in;  // the visitors need mutable access
  const std::string origin(origin_in);
  for (const auto& f : collect_fields(config)) f.check(origin);
  check_consistency(config, origin);
}

void apply_config_yaml(SaloamConfig& config, std::string_view yaml_text, std::string_view origin) {
  const YamlDocument document = load_yaml_document(yaml_text, "a configuration");
  if (!document.problem.empty()) throw ConfigError(fmt::format("{}: {}", origin, document.problem));
  const YAML::Node& root = document.root;
  SaloamConfig updated = config;  // `config` stays as it was when anything is wrong
  if (!root.IsNull()) apply_node(updated, root, "", std::string(origin), collect_fields(updated));  // null: empty file
  validate_config(updated, origin);
  config = std::move(updated);
}

SaloamConfig load_config(const std::filesystem::path& path) {
  SaloamConfig config;
  apply_config_yaml(config, read_file(path, kMaxConfigBytes, "configuration file"), path.string());
  return config;
}

namespace {

// Sets one key=value in `config`, checking every field's range (the
// cross-field rules are the caller's, once all values are set).
void set_override(SaloamConfig& config, std::string_view assignment, std::string origin = "") {
  const auto eq = assignment.find('=');
  if (eq == std::string_view::npos || eq == 0) {
    throw ConfigError(fmt::format("--set '{}': expected key=value", assignment));
  }
  if (origin.empty()) origin = fmt::format("--set {}", assignment);
  YAML::Node value;
  try {
    value = YAML::Load(std::string(assignment.substr(eq + 1)));
  } catch (const YAML::Exception& e) {
    throw ConfigError(fmt::format("{}: cannot parse value: {}", origin, e.what()));
  }
  const auto fields = collect_fields(config);
  set_by_key(fields, resolve_short_key(fields, std::string(assignment.substr(0, eq)), origin), value, origin);
  for (const auto& f : fields) f.check(origin);
}

}  // namespace

void apply_config_option(SaloamConfig& config, std::string_view option, std::string_view key, std::string_view value) {
  const std::string origin = fmt::format("{} {}", option, value);
  SaloamConfig updated = config;
  set_override(updated, fmt::format("{}={}", key, value), origin);
  validate_config(updated, origin);
  config = std::move(updated);
}

void apply_config_override(SaloamConfig& config, std::string_view assignment) {
  apply_config_overrides(config, {std::string(assignment)});
}

void apply_config_overrides(SaloamConfig& config, const std::vector<std::string>& assignments) {
  SaloamConfig updated = config;  // `config` stays as it was when anything is wrong
  for (const auto& assignment : assignments) set_override(updated, assignment);
  if (!assignments.empty()) validate_config(updated, fmt::format("--set {}", fmt::join(assignments, " --set ")));
  config = std::move(updated);
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
      out << YAML::Key << f.key.substr(dot + 1) << YAML::Value << f.get() << YAML::Comment(doc_with_range(f));
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
