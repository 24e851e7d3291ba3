#include "command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>

#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"
#include "saloam/segmentation/segmenter.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/io/intensity_scale.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/sources/open_source.hpp"
#include "saloam/sources/udp_socket.hpp"
#include "saloam/sources/sensor_guess.hpp"

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

SaloamConfig ConfigOptions::resolve_for_map(const SaloamConfig& map_config) const {
  SaloamConfig config = config_file.empty() ? map_config : load_config(config_file_path(config_file));
  apply_config_overrides(config, overrides);
  if (config.loop.detector != map_config.loop.detector) {
    throw ConfigError(fmt::format("loop.detector is {}, but the map's descriptors were made for {}", config.loop.detector,
                                  map_config.loop.detector));
  }
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

void use_model_option(const std::string& given, SaloamConfig& config) {
  if (uses_sgpr(parse_place_detector(config.loop.detector))) {
    config.loop.sgpr_model = sgpr_model_path(given, config).string();
  } else {
    refuse_unused_model(given, config.loop.detector);
  }
}

void refuse_unused_model(const std::string& given, const std::string& detector) {
  if (given.empty()) return;
  throw ConfigError(fmt::format("--model {}: the {} detector has no model (--model gives the SGPR weights of the sgpr "
                                "and hybrid detectors)",
                                given, detector));
}

std::filesystem::path segmentation_plugin_path() {
  // The Python module runs inside python3: it names the folder it found.
  if (const char* env = std::getenv("SALOAM_PLUGIN_DIR"); env && *env) {
    return std::filesystem::path(env) / kSegmentationPlugin;
  }
  const auto bin = program_dir();
  if (!bin) return kSegmentationPlugin;
  std::error_code error;
  if (const auto beside = *bin / kSegmentationPlugin; std::filesystem::is_regular_file(beside, error)) return beside;
  return (*bin / SALOAM_INSTALL_PLUGIN_RELATIVE / kSegmentationPlugin).lexically_normal();
}

std::filesystem::path segmenter_description_path(const std::string& given, const std::string& projection,
                                                 const SaloamConfig& config) {
  const std::filesystem::path model = !given.empty() ? given : config.segmentation.model;
  const std::string option = !given.empty() ? "--segmenter" : "segmentation.model";
  std::error_code error;
  if (!projection.empty() && model.extension() != ".pt") {
    // Every option used or refused (issue #39): a description names its own network.
    throw ConfigError(model.empty()
                          ? fmt::format("--projection {}: describes a TorchScript network given as --segmenter NET.pt; "
                                        "there is none",
                                        projection)
                          : fmt::format("--projection {}: only for a TorchScript {} (.pt); {} is a description that "
                                        "names its own network",
                                        projection, option, model.string()));
  }
  if (model.extension() == ".pt" && !std::filesystem::is_regular_file(model, error)) {
    throw ConfigError(fmt::format("{} {}: no such TorchScript file", option, model.string()));
  }
  if (model.empty()) {
    const auto shipped = data_dir() / "models" / "segmenter" / "saloam.yaml";
    if (std::filesystem::is_regular_file(shipped, error)) return shipped;
    throw ConfigError(fmt::format("--segment needs a model: pass --segmenter FILE (the shipped model is missing from {}; "
                                  "set SALOAM_DATA_DIR if saloam was moved)",
                                  shipped.parent_path().string()));
  }
  if (!projection.empty()) return projection;
  // A bare name (`--segmenter saloam_real`) names a shipped model, unless a file of that name is here.
  if (!model.has_parent_path() && !model.has_extension() && !std::filesystem::exists(model, error)) {
    const auto shipped = data_dir() / "models" / "segmenter" / (model.string() + ".yaml");
    if (std::filesystem::is_regular_file(shipped, error)) return shipped;
  }
  if (model.extension() != ".pt") return model;
  auto beside = model;
  beside.replace_extension(".yaml");
  if (std::filesystem::is_regular_file(beside, error)) return beside;
  throw ConfigError(fmt::format("--segmenter {}: a TorchScript model needs a description of its projection and classes: "
                                "--projection FILE.yaml, or {} beside it (docs/segmentation.md)",
                                model.string(), beside.string()));
}

void SegmentOptions::add_to(CLI::App& app) {
  app.add_flag("--segment", segment,
               "Label every scan in-process with the segmentation network (the shipped model unless --segmenter)");
  app.add_option("--segmenter", segmenter,
                 "Segmentation model: a description (.yaml), a TorchScript network (.pt) with its description beside "
                 "it or in --projection, or a shipped model's name (saloam_real: fine-tuned on real KITTI scans); "
                 "implies --segment");
  app.add_option("--projection", projection, "Description (.yaml) of a --segmenter TorchScript network's projection");
}

int forward_to_program(const std::string& name, const std::vector<std::string>& arguments) {
  const auto bin = program_dir();
  const auto program = bin ? *bin / name : std::filesystem::path(name);
  std::error_code error;
  if (!bin || !std::filesystem::is_regular_file(program, error)) {
    spdlog::error("this saloam was built without libtorch: {} is not available (install libtorch-dev, e.g. "
                  "scripts/install_deps.sh, and rebuild)",
                  program.string());
    return 2;
  }
  std::vector<std::string> args{program.string()};
  if (spdlog::get_level() >= spdlog::level::warn) args.emplace_back("--quiet");
  if (spdlog::get_level() <= spdlog::level::debug) args.emplace_back("--verbose");
  args.insert(args.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  execv(argv[0], argv.data());
  throw InputError(program, std::string("cannot run: ") + std::strerror(errno));
}

std::optional<SegmentationStageOptions> SegmentOptions::stage(const SaloamConfig& config) const {
  if (!enabled()) return std::nullopt;
  SegmentationStageOptions stage;
  const std::filesystem::path description = segmenter_description_path(segmenter, projection, config);
  spdlog::info("segmenting with {}", description.string());
  stage.model = read_segmenter_spec(description);
  const std::filesystem::path model = !segmenter.empty() ? segmenter : config.segmentation.model;
  if (model.extension() == ".pt") {
    // The network run is the one given, never one named inside its description.
    stage.model.network.format = NetworkFormat::kTorchScript;
    stage.model.network.weights = std::filesystem::absolute(model).string();
  }
  stage.plugin = segmentation_plugin_path();
  stage.rings = config.odometry.features;
  stage.workers = config.segmentation.workers;
  stage.lookahead = static_cast<std::size_t>(config.segmentation.lookahead);
  return stage;
}

void SourceArgs::add_to(CLI::App& app, const std::string& path_help) {
  app.add_option("SEQ_DIR", path,
                 path_help + "; or a KITTI raw drive, a folder of .pcd/.ply files, a ROS 1 bag, a ROS 2 bag (folder or "
                             ".db3), an .mcap file, a sensor's .pcap capture")
      ->required();
  app.add_option("--format", format,
                 "Layout of SEQ_DIR: auto (detected), semantickitti, kitti-raw, pcd, ply, rosbag, rosbag2, mcap, pcap")
      ->check(CLI::IsMember(scan_format_names()))
      ->capture_default_str();
  app.add_option("--topic", topic, "ROS 1/2 bag or MCAP topic of sensor_msgs/PointCloud2 (default: the only one)");
  app.add_option("--metadata", metadata,
                 "A capture's sensor metadata: Ouster's metadata JSON, or a Velodyne calibration YAML "
                 "(velodyne_pointcloud's; default: NAME.json / NAME.yaml beside NAME.pcap)");
  app.add_option("--sensor", sensor,
                 "Sensor profile: auto (guessed from the first scan), none, a shipped one (hdl64e, hdl32e, vlp16, os1-64, "
                 "os1-128: config/sensors/) or a profile file")
      ->capture_default_str();
  app.add_option("--intensity-scale", intensity_scale,
                 "What the scans' intensity values are divided by to make remission 0..1: auto (from the field's "
                 "type or the first scan's values), 1 (KITTI), 255 (Velodyne drivers, most PCD/PLY), 65535 (uint16)")
      ->check(CLI::IsMember(intensity_scale_names()))
      ->capture_default_str();
  app.add_option("--labels", labels, "Folder of .label files (named like the scans) instead of SEQ_DIR/labels");
  app.add_option("--frames", frames, "Frame range A:B (B exclusive; A: = to the end)");
  segment.add_to(app);
}

void SourceArgs::add_live_to(CLI::App& app) {
  accepts_live = true;
  CLI::Option* source = app.get_option("SEQ_DIR");
  source->description(source->get_description() +
                      "; or udp://[ADDRESS]:PORT: a sensor's packets as they arrive (--sensor vlp16|hdl32e|hdl64e, "
                      "or an Ouster's --metadata META.json)");
  app.add_option("--idle-timeout", idle_timeout_s,
                 "A live source (SEQ_DIR udp://[ADDRESS]:PORT): end when no packet arrived for this many seconds "
                 "(from the start too; 0: only Ctrl-C or --frames end it)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--queue", queue_frames,
                 "A live source: frames held for a run that falls behind; beyond, the oldest whole frame is dropped "
                 "and counted")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1000}))
      ->capture_default_str();
}

void SourceArgs::add_with_no_calib_to(CLI::App& app) {
  add_to(app, "A SemanticKITTI sequence folder");
  add_no_calib_flag(app, no_calib);
}

namespace {
SourceOptions source_options(const SourceArgs& args, bool ignore_labels) {
  SourceOptions options;
  const auto format = scan_format_from_name(args.format);
  if (!format) throw ConfigError(fmt::format("--format {}: not one of {}", args.format, fmt::join(scan_format_names(), ", ")));
  options.format = *format;
  options.topic = args.topic;
  if (!args.metadata.empty()) options.metadata = args.metadata;
  options.intensity_scale = parse_intensity_scale(args.intensity_scale);
  if (!args.labels.empty()) options.labels = args.labels;
  options.ignore_labels = ignore_labels;
  options.ignore_calib = args.no_calib;
  options.frames = FrameRange::parse(args.frames);
  options.live.sensor = args.sensor;
  options.live.idle_timeout_s = args.idle_timeout_s;
  options.live.queue_frames = args.queue_frames;
  return options;
}
}  // namespace

PathRules& SourceArgs::add_inputs(PathRules& rules) const {
  if (!is_udp_url(path)) rules.input("SEQ_DIR", path);  // an address: no file an output could replace
  return rules.input("--labels", labels).input("--metadata", metadata);
}

std::unique_ptr<FrameSource> SourceArgs::open(bool ignore_labels, SaloamConfig& config, SensorChoice* chosen) const {
  if (segment.enabled() && ignore_labels)
    throw ConfigError("--segment labels the scans, but this run does not use labels (--no-semantics, or a label-free "
                      "method): leave out one of them");
  if (segment.enabled() && !labels.empty()) throw ConfigError("give --labels DIR or --segment, not both");
  if (is_udp_url(path) && !accepts_live) {
    throw ConfigError(fmt::format("{}: a live source is run by odom, slam and localize; record it to read it here "
                                  "(tcpdump -w CAPTURE.pcap udp port PORT)",
                                  path));
  }
  SourceOptions options = source_options(*this, ignore_labels);
  options.segmentation = segment.stage(config);  // checks the model before anything is read
  auto reader = open_reader(path, options);
  if (const auto intensity = intensity_note(reader->info().notes)) spdlog::info("{}", *intensity);
  SensorChoice choice = choose_sensor(sensor, *reader);
  if (choice.profile) {
    apply_sensor_profile(*choice.profile, config.odometry.features);
    validate_config(config, fmt::format("--sensor {}", choice.profile->name));
    spdlog::info("sensor: {}, {}", choice.profile->title(), choice.how);
  }
  if (options.segmentation) options.segmentation->rings = config.odometry.features;
  options.sensor_lasers = choice.lasers;
  if (chosen) *chosen = std::move(choice);
  return add_stages(std::move(reader), options);
}

std::vector<SensorProfile> shipped_sensor_profiles() { return load_sensor_profiles(data_dir() / "config" / "sensors"); }

SensorProfile sensor_profile(const std::string& name_or_file) {
  const std::filesystem::path given(name_or_file);
  std::error_code error;
  if (std::filesystem::is_regular_file(given, error)) return load_sensor_profile(given);
  const auto shipped = shipped_sensor_profiles();
  for (const auto& p : shipped) {
    if (p.name == name_or_file) return p;
  }
  std::vector<std::string> names;
  for (const auto& p : shipped) names.push_back(p.name);
  throw ConfigError(fmt::format("--sensor {}: no such profile file, nor a shipped profile (in {}: {}; or auto, none)",
                                name_or_file, (data_dir() / "config" / "sensors").string(), fmt::join(names, ", ")));
}

SensorChoice choose_sensor(const std::string& sensor, FrameSource& source) {
  SensorChoice choice;
  if (sensor == "none") {
    choice.how = "none (--sensor none)";
    return choice;
  }
  if (sensor != "auto") {
    choice.profile = sensor_profile(sensor);
    choice.how = fmt::format("as given (--sensor {})", sensor);
    choice.lasers = static_cast<std::size_t>(choice.profile->beams());
    return choice;
  }
  if (!source.info().rereadable || source.size() == 0) {
    choice.how = "none: a stream cannot be looked at before the run (give --sensor NAME)";
    return choice;
  }
  const auto profiles = shipped_sensor_profiles();
  LabelledCloud first;
  try {
    first = source.scan(0);
  } catch (const InputError&) {
    // The run reads it again and fails there, as a run does (its outputs
    // say so); the guess only stands aside.
    choice.how = "none: the first scan cannot be read";
    return choice;
  }
  const SensorGuess guess = guess_sensor(first, profiles);
  choice.profile = profiles[guess.profile];
  // The guess is the nearest profile; a first scan numbering its rings
  // beyond the profile's lasers says it is not the sensor itself, so its
  // rings are not held to that count.
  const auto lasers = static_cast<std::size_t>(choice.profile->beams());
  const bool rings_fit = !first.has_rings() || std::ranges::all_of(first.ring, [&](auto r) { return r < lasers; });
  choice.lasers = rings_fit ? lasers : 0;
  std::string subset;
  if (auto kept = laser_subset(*choice.profile, guess.lasers)) {
    subset = fmt::format(", {} of its {} lasers", kept->beams(), choice.profile->beams());
    choice.profile = std::move(kept);
  }
  choice.how =
      fmt::format("guessed from the first scan: {}{} (--sensor NAME to choose another)", guess.found(), subset);
  return choice;
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
