// `saloam config`: print the effective configuration as YAML.

#include <iostream>

#include "command.hpp"

namespace saloam::cli {
namespace {

const CommandRegistration kRegistration{Command{
    "config", "Print the effective configuration (defaults, --config file, --set overrides) as YAML", 90,
    [](CLI::App& app) {
      auto options = std::make_shared<ConfigOptions>();
      options->add_to(app);
      return [options] {
        std::cout << config_to_yaml(options->resolve());
        return 0;
      };
    }}};

}  // namespace
}  // namespace saloam::cli
