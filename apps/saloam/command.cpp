#include "command.hpp"

#include <cmath>
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

void add_no_calib_flag(CLI::App& app, bool& no_calib) {
  app.add_flag("--no-calib", no_calib,
               "Run without calib.txt (ignored if present): poses.txt holds LiDAR-frame poses, not KITTI's camera "
               "frame");
}

CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0.0;
        if (CLI::detail::lexical_cast(text, value) && std::isfinite(value) && value > 0.0) return "";
        return "must be a positive number, got '" + text + "'";
      },
      "POSITIVE");
}

CLI::Validator non_negative_integer() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
        if (digits && text.size() <= 18) return "";
        return "must be a whole number (0 or more), got '" + text + "'";
      },
      "UINT");
}

std::filesystem::path shared_dir() {
  if (const char* env = std::getenv("SALOAM_SHARED_DIR")) return env;
  return SALOAM_DEFAULT_SHARED_DIR;
}

}  // namespace saloam::cli
