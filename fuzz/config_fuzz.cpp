// YAML configuration (apply_config_yaml, what load_config reads files with).
// Accepted text must give a configuration that passes validate_config and
// survives config_to_yaml and back unchanged.

#include "fuzz_support.hpp"
#include "saloam/core/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  const std::string origin = "config.yaml";
  const SaloamConfig defaults;
  SaloamConfig config;
  try {
    apply_config_yaml(config, fuzz::as_text(data, size), origin);
  } catch (const ConfigError& e) {
    SALOAM_FUZZ_CHECK(std::string_view(e.what()).starts_with(origin + ":"));
    SALOAM_FUZZ_CHECK(config_to_yaml(config) == config_to_yaml(defaults));  // left unchanged
    return 0;
  }
  validate_config(config, origin);
  const std::string yaml = config_to_yaml(config);
  SaloamConfig again;
  apply_config_yaml(again, yaml, "round trip");
  SALOAM_FUZZ_CHECK(config_to_yaml(again) == yaml);
  return 0;
}
