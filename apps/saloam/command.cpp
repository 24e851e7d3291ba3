#include "command.hpp"

#include <cstdlib>

namespace saloam::cli {

std::vector<Command>& command_registry() {
  static std::vector<Command> registry;
  return registry;
}

void ConfigOptions::add_to(CLI::App& app) {
  app.add_option("--config", config_file, "YAML configuration file (see config/saloam.yaml)")->check(CLI::ExistingFile);
  app.add_option("--set", overrides, "Override a configuration value, e.g. --set odometry.alpha=0.2 (repeatable)")
      ->take_all();
}

SaloamConfig ConfigOptions::resolve() const {
  SaloamConfig config = config_file.empty() ? SaloamConfig{} : load_config(config_file);
  apply_config_overrides(config, overrides);
  return config;
}

std::filesystem::path shared_dir() {
  if (const char* env = std::getenv("SALOAM_SHARED_DIR")) return env;
  return SALOAM_DEFAULT_SHARED_DIR;
}

}  // namespace saloam::cli
