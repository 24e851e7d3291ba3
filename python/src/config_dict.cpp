#include "config_dict.hpp"

#include <cmath>
#include <string>
#include <type_traits>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "command.hpp"  // cli::config_file_path: a shipped configuration by name
#include "saloam/core/error.hpp"

namespace saloam::python {
namespace {

template <class T>
py::object field_value(const T& member) {
  if constexpr (std::is_same_v<T, ClassValueMap>) {
    py::dict d;
    for (const auto& [name, value] : member) d[py::str(name)] = value;
    return d;
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    py::list l;
    for (const double v : member) l.append(v);
    return l;
  } else {
    return py::cast(member);
  }
}

/// d[a][b]... for the section "a.b", made as needed.
py::dict section_dict(py::dict root, std::string_view section) {
  py::dict d = std::move(root);
  std::size_t start = 0;
  while (start <= section.size()) {
    const std::size_t dot = std::min(section.find('.', start), section.size());
    const py::str key(std::string(section.substr(start, dot - start)));
    if (!d.contains(key)) d[key] = py::dict();
    d = d[key].cast<py::dict>();
    start = dot + 1;
  }
  return d;
}

void emit(YAML::Emitter& out, const py::handle& value, const std::string& key);

/// A dict with dotted keys ("odometry.features.alpha") written as nested maps.
void emit_map(YAML::Emitter& out, const py::dict& d, const std::string& prefix) {
  // Nest dotted keys first, so that {"odometry.alpha": 1, "odometry": {...}} merge.
  py::dict nested;
  for (const auto& [k, v] : d) {
    if (!py::isinstance<py::str>(k))
      throw ConfigError(fmt::format("config: key {} of '{}' is not a string", py::repr(k).cast<std::string>(),
                                    prefix.empty() ? "<root>" : prefix));
    const auto name = k.cast<std::string>();
    const auto dot = name.find('.');
    if (dot == std::string::npos || dot == 0) {
      if (nested.contains(k) && py::isinstance<py::dict>(nested[k]) && py::isinstance<py::dict>(v)) {
        nested[k].cast<py::dict>().attr("update")(v);
      } else {
        nested[k] = v;
      }
      continue;
    }
    const py::str head(name.substr(0, dot));
    if (!nested.contains(head)) nested[head] = py::dict();
    if (!py::isinstance<py::dict>(nested[head]))
      throw ConfigError(fmt::format("config: '{}' is given as a value and as a section", name.substr(0, dot)));
    nested[head].cast<py::dict>()[py::str(name.substr(dot + 1))] = v;
  }
  out << YAML::BeginMap;
  for (const auto& [k, v] : nested) {
    const auto name = k.cast<std::string>();
    out << YAML::Key << YAML::DoubleQuoted << name << YAML::Value;
    emit(out, v, prefix.empty() ? name : prefix + "." + name);
  }
  out << YAML::EndMap;
}

void emit(YAML::Emitter& out, const py::handle& value, const std::string& key) {
  if (py::isinstance<py::dict>(value)) {
    emit_map(out, value.cast<py::dict>(), key);
  } else if (py::isinstance<py::bool_>(value)) {
    out << (value.cast<bool>() ? "true" : "false");
  } else if (py::isinstance<py::int_>(value) || py::hasattr(value, "__index__")) {
    out << py::str(value.attr("__index__")()).cast<std::string>();
  } else if (py::isinstance<py::float_>(value) || py::hasattr(value, "__float__")) {
    const double v = py::float_(py::reinterpret_borrow<py::object>(value)).cast<double>();
    out << (std::isnan(v) ? std::string(".nan") : std::isinf(v) ? std::string(v > 0 ? ".inf" : "-.inf")
                                                                : fmt::format("{}", v));
  } else if (py::isinstance<py::str>(value)) {
    out << YAML::DoubleQuoted << value.cast<std::string>();
  } else if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    out << YAML::Flow << YAML::BeginSeq;
    for (const py::handle item : value) emit(out, item, key);
    out << YAML::EndSeq;
  } else {
    throw ConfigError(fmt::format("config: '{}' has a value of type {} (numbers, booleans, strings, lists and dicts "
                                  "only)",
                                  key, py::str(py::type::of(value).attr("__name__")).cast<std::string>()));
  }
}

}  // namespace

py::dict config_to_dict(const SaloamConfig& config_in) {
  SaloamConfig config = config_in;  // the visitors need mutable access
  py::dict root;
  visit_sections(config, [&](std::string_view section, auto& s) {
    py::dict d = section_dict(root, section);
    visit_fields(s, [&](std::string_view name, auto& member, auto&&...) { d[py::str(std::string(name))] = field_value(member); });
  });
  return root;
}

SaloamConfig config_from_python(const py::handle& value, const std::vector<std::string>& overrides) {
  SaloamConfig config;
  if (value.is_none()) {
    // the defaults
  } else if (py::isinstance<py::dict>(value)) {
    YAML::Emitter out;
    emit(out, value, "");
    apply_config_yaml(config, out.c_str(), "config");
  } else if (py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__")) {
    const auto name = py::str(py::module_::import("os").attr("fspath")(value)).cast<std::string>();
    config = load_config(cli::config_file_path(name));
  } else {
    throw py::type_error(fmt::format("config must be None, a dict, or a file or shipped configuration's name, not {}",
                                     py::str(py::type::of(value).attr("__name__")).cast<std::string>()));
  }
  apply_config_overrides(config, overrides);
  return config;
}

}  // namespace saloam::python
