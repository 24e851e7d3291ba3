#pragma once
// The configuration as a Python dict: the keys of `saloam config` (nested
// sections, e.g. d["odometry"]["features"]["alpha"]), made by the same
// field visitors as the YAML. A dict given back is written as YAML and
// applied over the defaults by apply_config_yaml: one validation, the same
// messages (ConfigError) as a --config file.

#include <pybind11/pybind11.h>

#include "saloam/core/config.hpp"

namespace saloam::python {

namespace py = pybind11;

py::dict config_to_dict(const SaloamConfig& config);

/// None: the defaults; a dict (nested sections, or dotted keys such as
/// "odometry.features.alpha" at any level): applied over the defaults; a str
/// or os.PathLike: a YAML file, or the name of a shipped configuration
/// ("real_kitti", "paper"). `overrides`: "key=value" strings on top, as --set.
SaloamConfig config_from_python(const py::handle& value, const std::vector<std::string>& overrides = {});

}  // namespace saloam::python
