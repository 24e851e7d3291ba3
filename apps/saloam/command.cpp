#include "command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "saloam/core/error.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/sources/open_source.hpp"

namespace saloam::cli {

std::vector<Command>& command_registry() {
  static std::vector<Command> registry;
  return registry;
}

void ConfigOptions::add_to(CLI::App& app) {
  app.add_option("--config", config_file,
                 "YAML configuration file, or the name of a shipped one (paper, real_kitti, saloam: see config/)");
  app.add_option("--set", overrides, "Override a configuration value, e.g. --set odometry.alpha=0.2 (repeatable)")
      ->take_all();
}

SaloamConfig ConfigOptions::resolve() const {
  SaloamConfig config = config_file.empty() ? SaloamConfig{} : load_config(config_file_path(config_file));
  apply_config_overrides(config, overrides);
  return config;
}

std::optional<std::filesystem::path> program_dir() {
  std::error_code error;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return std::nullopt;
  return exe.parent_path();
}

namespace {

std::optional<std::filesystem::path> installed_data_dir() {
  const auto bin = program_dir();
  if (!bin) return std::nullopt;
  const auto dir = (*bin / SALOAM_INSTALL_DATA_RELATIVE).lexically_normal();
  std::error_code error;
  if (!std::filesystem::is_directory(dir / "config", error)) return std::nullopt;
  return dir;
}

std::vector<std::string> shipped_configs() {
  std::vector<std::string> names;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(data_dir() / "config", error)) {
    if (entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

std::filesystem::path data_dir() {
  if (const char* env = std::getenv("SALOAM_DATA_DIR"); env && *env) return env;
  if (auto installed = installed_data_dir()) return *installed;
  return SALOAM_SOURCE_DATA_DIR;
}

std::filesystem::path config_file_path(const std::string& name) {
  const std::filesystem::path given(name);
  std::error_code error;
  if (std::filesystem::is_directory(given, error)) throw ConfigError(fmt::format("--config {}: is a directory", name));
  if (std::filesystem::exists(given, error)) return given;
  if (!given.has_parent_path()) {
    auto shipped = data_dir() / "config" / given;
    if (shipped.extension() != ".yaml") shipped += ".yaml";
    if (std::filesystem::is_regular_file(shipped, error)) return shipped;
  }
  throw ConfigError(fmt::format("--config {}: no such file, nor a shipped configuration of that name (in {}: {})", name,
                                (data_dir() / "config").string(), fmt::join(shipped_configs(), ", ")));
}

std::filesystem::path sgpr_model_path(const std::string& given, const SaloamConfig& config) {
  if (!given.empty()) return given;
  if (!config.loop.sgpr_model.empty()) return config.loop.sgpr_model;
  const auto shipped = data_dir() / "models" / "sgpr" / "saloam.sgw";
  std::error_code error;
  if (std::filesystem::is_regular_file(shipped, error)) return shipped;
  throw ConfigError(fmt::format(
      "SGPR needs weights: pass --model FILE.sgw or --set loop.sgpr_model=FILE.sgw (the shipped model is missing "
      "from {}; set SALOAM_DATA_DIR if saloam was moved)",
      shipped.parent_path().string()));
}

void SourceArgs::add_to(CLI::App& app, const std::string& path_help) {
  app.add_option("SEQ_DIR", path, path_help + "; or a KITTI raw drive, a folder of .pcd/.ply files, a ROS 1 bag")
      ->required();
  app.add_option("--format", format,
                 "Layout of SEQ_DIR: auto (detected), semantickitti, kitti-raw, pcd, ply, rosbag")
      ->check(CLI::IsMember(scan_format_names()))
      ->capture_default_str();
  app.add_option("--topic", topic, "ROS bag topic of sensor_msgs/PointCloud2 (default: the only one)");
  app.add_option("--labels", labels, "Folder of .label files (named like the scans) instead of SEQ_DIR/labels");
  app.add_option("--frames", frames, "Frame range A:B (B exclusive; A: = to the end)");
}

namespace {
SourceOptions source_options(const SourceArgs& args, bool ignore_labels) {
  SourceOptions options;
  const auto format = scan_format_from_name(args.format);
  if (!format) throw ConfigError(fmt::format("--format {}: not one of {}", args.format, fmt::join(scan_format_names(), ", ")));
  options.format = *format;
  options.topic = args.topic;
  if (!args.labels.empty()) options.labels = args.labels;
  options.ignore_labels = ignore_labels;
  options.ignore_calib = args.no_calib;
  options.frames = FrameRange::parse(args.frames);
  return options;
}
}  // namespace

std::unique_ptr<FrameSource> SourceArgs::open(bool ignore_labels) const {
  return open_source(path, source_options(*this, ignore_labels));
}

void add_no_calib_flag(CLI::App& app, bool& no_calib) {
  app.add_flag("--no-calib", no_calib,
               "Ignore calib.txt: work in the LiDAR frame (pose files hold LiDAR-frame poses, poses.txt is taken as "
               "such), as for a source without calib.txt");
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

}  // namespace saloam::cli
