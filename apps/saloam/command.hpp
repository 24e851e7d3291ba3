#pragma once
// Subcommand registry of the `saloam` program. Each cmd_*.cpp registers one
// subcommand with a static `CommandRegistration`; main() builds the CLI from
// the registry. Commands only parse options, call the library and print.

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "saloam/core/config.hpp"
#include "saloam/core/path_rules.hpp"
#include "saloam/core/sensor_profile.hpp"
#include "saloam/segmentation/segmented_source.hpp"
#include "saloam/io/frame_source.hpp"
#include "saloam/sources/source_options.hpp"

namespace saloam::cli {

/// Adds options to `app` and returns the function that runs the command
/// (called after parsing; returns the exit code).
using CommandSetup = std::function<std::function<int()>(CLI::App& app)>;

struct Command {
  std::string name;
  std::string description;
  int order;  ///< position in --help
  CommandSetup setup;
};

std::vector<Command>& command_registry();

struct CommandRegistration {
  explicit CommandRegistration(Command command) { command_registry().push_back(std::move(command)); }
};

/// --config FILE|NAME and --set key=value (repeatable), shared by every
/// command that runs the pipeline. NAME (no folder, e.g. `real_kitti`) is a
/// configuration shipped in data_dir()/config. Call `resolve()` after parsing.
struct ConfigOptions {
  std::string config_file;
  std::vector<std::string> overrides;
  void add_to(CLI::App& app);
  [[nodiscard]] SaloamConfig resolve() const;
  /// The configuration of a run in a saved map: the map's (`map_config`,
  /// whose detector made its descriptors), a --config instead, --set on
  /// top; ConfigError when the detector is no longer the map's.
  [[nodiscard]] SaloamConfig resolve_for_map(const SaloamConfig& map_config) const;
};

/// --segment, --segmenter FILE and --projection FILE of the commands that can
/// label raw scans in-process.
struct SegmentOptions {
  bool segment = false;
  std::string segmenter;
  std::string projection;
  void add_to(CLI::App& app);
  /// True when the run segments (--segment, or a --segmenter given).
  [[nodiscard]] bool enabled() const { return segment || !segmenter.empty(); }
  /// The segmentation stage these options ask for (the model read and
  /// checked; workers, look-ahead and ring recovery from `config`), or none.
  [[nodiscard]] std::optional<SegmentationStageOptions> stage(const SaloamConfig& config) const;
};

/// The options that choose a run's frames, shared by the commands that read
/// a source (odom, slam, place-eval, bench, info, convert, segment): SEQ_DIR
/// (any layout of sources/source_options.hpp), --format, --topic, --metadata, --sensor,
/// --intensity-scale, --labels, --frames and the segmentation's options;
/// commands where calibration matters add --no-calib (add_no_calib_flag).
/// Call `open()` after parsing.
/// The sensor profile a run works with (--sensor), and how it was chosen.
struct SensorChoice {
  std::optional<SensorProfile> profile;  ///< none with --sensor none
  std::string how;                       ///< "given (--sensor vlp16)", "guessed from the first scan: ..."
  /// Rings at or beyond this fit no laser of the sensor (SourceOptions::sensor_lasers): the whole
  /// profile's laser count (also when a subset of its lasers was kept); 0: not checked (no profile,
  /// or a guess whose first scan has rings beyond the guessed profile's lasers).
  std::size_t lasers = 0;
};

/// The sensor profiles shipped in data_dir()/config/sensors/ (by name).
std::vector<SensorProfile> shipped_sensor_profiles();
/// --sensor NAME (a shipped profile) or FILE (a profile of one's own,
/// format in core/sensor_profile.hpp); ConfigError naming the shipped ones
/// when it is neither.
SensorProfile sensor_profile(const std::string& name_or_file);
/// What --sensor `sensor` means for `source`: "none" (no profile: rings from
/// the storage order or the HDL-64E/HDL-32E/VLP-16 layouts, as before
/// profiles), a profile by name or file, or "auto": the shipped profile that
/// fits the source's first scan best (sources/sensor_guess.hpp), cut down to
/// the lasers found when the scan keeps only some of them (laser_subset); none when
/// that scan cannot be read (the run then fails on it as it would anyway).
SensorChoice choose_sensor(const std::string& sensor, FrameSource& source);

struct SourceArgs {
  std::string path;
  std::string format = "auto";
  std::string sensor = "auto";
  std::string topic;
  std::string metadata;  ///< --metadata: a capture's Ouster JSON or Velodyne calibration YAML
  std::string intensity_scale = "auto";
  std::string labels;
  std::string frames;
  bool no_calib = false;
  SegmentOptions segment;  ///< --segment, --segmenter, --projection
  /// A live source (SEQ_DIR udp://[ADDRESS]:PORT) is taken: set by add_live_to().
  bool accepts_live = false;
  double idle_timeout_s = LiveOptions{}.idle_timeout_s;  ///< --idle-timeout
  std::size_t queue_frames = LiveOptions{}.queue_frames;  ///< --queue
  void add_to(CLI::App& app, const std::string& path_help);
  /// The live source's options (--idle-timeout, --queue) of the commands
  /// that run on one as it comes (odom, slam, localize); others refuse udp://.
  void add_live_to(CLI::App& app);
  /// add_to() and --no-calib for the commands that take a source as it is
  /// (info, convert): SEQ_DIR is "A SemanticKITTI sequence folder" or any
  /// other layout.
  void add_with_no_calib_to(CLI::App& app);
  /// open_source() with these options; whether labels are read is the
  /// command's choice (ConfigError when it ignores them but --segment asks
  /// for them). The intensity range the reader found or was given is said
  /// in one log line. The sensor (--sensor, chosen on the reader and said in one
  /// log line) goes into config.odometry.features (apply_sensor_profile)
  /// before `config` sets up the segmentation stage; `chosen` receives it.
  [[nodiscard]] std::unique_ptr<FrameSource> open(bool ignore_labels, SaloamConfig& config,
                                                  SensorChoice* chosen = nullptr) const;
  /// The paths it reads (SEQ_DIR, --labels) as inputs of `rules`.
  PathRules& add_inputs(PathRules& rules) const;
};

/// The folder of the running program (from /proc/self/exe); none when it
/// cannot be read. Installed data and the trainer are found from it.
std::optional<std::filesystem::path> program_dir();

/// Where saloam's own data lie (config/*.yaml, models/): $SALOAM_DATA_DIR when
/// set; else <prefix>/share/saloam when the program runs installed as
/// <prefix>/bin/saloam; else the source tree it was built from.
std::filesystem::path data_dir();

/// The configuration file meant by `--config name`: the file itself, or for a
/// bare name data_dir()/config/<name>[.yaml]; ConfigError naming both places otherwise.
std::filesystem::path config_file_path(const std::string& name);

/// The SGPR weights to load: `given` (--model), else the config's
/// loop.sgpr_model, else the model shipped in data_dir()/models/sgpr/saloam.sgw;
/// ConfigError saying how to pass one when there is none.
std::filesystem::path sgpr_model_path(const std::string& given, const SaloamConfig& config);
/// config.loop.sgpr_model = sgpr_model_path(given, config) when the
/// configured detector uses SGPR; else refuse_unused_model.
void use_model_option(const std::string& given, SaloamConfig& config);
/// ConfigError when --model was given (`given` not empty) for `detector`,
/// which has no model: an option is used or refused, never ignored.
void refuse_unused_model(const std::string& given, const std::string& detector);
/// The network plugin of the segmentation (beside the program in a build
/// tree, in <prefix>/lib/saloam when installed; in $SALOAM_PLUGIN_DIR when
/// set, as the Python module sets it); it exists only in builds with libtorch.
std::filesystem::path segmentation_plugin_path();

/// The segmentation model to load: `given` (--segmenter), else the config's
/// segmentation.model, else the shipped data_dir()/models/segmenter/saloam.yaml.
/// A bare name without extension (`saloam_real`) is a shipped model's
/// (data_dir()/models/segmenter/NAME.yaml) when no file of that name is here.
/// A TorchScript file (.pt) needs its description: `projection` (--projection
/// FILE.yaml) or the .yaml of the same name beside it. ConfigError saying how
/// to pass one when there is none.
std::filesystem::path segmenter_description_path(const std::string& given, const std::string& projection,
                                                 const SaloamConfig& config);

/// Replaces this process by the program `name` beside saloam (a trainer
/// built only with libtorch), handing it `arguments` and the verbosity.
/// Returns 2 with a message when the program was not built.
int forward_to_program(const std::string& name, const std::vector<std::string>& arguments);

/// --no-calib of the runs (odom, slam, place-eval): calib.txt is not read even
/// when present, and the run works in the LiDAR frame, as it does for a
/// source without calib.txt.
void add_no_calib_flag(CLI::App& app, bool& no_calib);

/// Checks for numeric options whose messages name the value: CLI11's
/// PositiveNumber prints its range as 300-digit numbers, and an unsigned
/// option silently wraps -1 to 18446744073709551615.
CLI::Validator positive_number();
CLI::Validator non_negative_integer();

}  // namespace saloam::cli
