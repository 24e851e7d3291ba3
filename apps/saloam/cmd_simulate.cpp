// `saloam simulate`: write a synthetic sequence (HDL-64E sweeps, or those of
// a sensor profile, ray cast in a procedural street world along a preset or
// KITTI trajectory): a SemanticKITTI folder, or with --format any layout
// saloam reads (PCD, PLY and bags keep each point's ring and time), or a
// Velodyne packet capture.

#include <cctype>
#include <cmath>
#include <sstream>
#include <iostream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/imu/imu_noise.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/sim/class_shares.hpp"
#include "saloam/sim/simulated_source.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sim/trajectories.hpp"
#include "saloam/sources/sequence_writer.hpp"
#include "saloam/sources/velodyne_capture_writer.hpp"

namespace saloam::cli {
namespace {

struct SimulateArgs {
  std::string out;
  std::string trajectory;
  std::string calib;
  std::string preset;
  std::string frames;
  std::string labels;  ///< gt or noisy; SimulationOptions' by default
  std::string sensor;  ///< --sensor NAME|FILE
  std::string format = "semantickitti";
  bool azimuth_steps_given = false;
  SimulationOptions sim;  ///< --stride, --seed, --beams, --azimuth-steps and every default
  bool no_skew = false;
  bool no_dynamic = false;
  bool stats = false;
  std::vector<std::string> passes;  ///< --passes A:B[:reverse],...
  std::vector<std::string> mount_rpy;        ///< --mount-rpy "R P Y" [deg]
  std::vector<std::string> cloud_frame_rpy;  ///< --cloud-frame-rpy "R P Y" [deg]
};

/// Roll, pitch, yaw [deg] of an option given as three numbers, one word or
/// three ("0 20 0" or 0 20 0).
Eigen::Vector3d rpy_option(const std::vector<std::string>& words, const char* option) {
  if (words.empty()) return Eigen::Vector3d::Zero();
  std::string text;
  for (const auto& w : words) text += w + " ";
  std::istringstream in(text);
  std::vector<double> values;
  for (std::string number; in >> number;) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(number, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != number.size() || !std::isfinite(v) || std::abs(v) > 360.0) {
      throw ConfigError(fmt::format("{} '{}': '{}' is no angle in [-360, 360] deg", option, text.substr(0, text.size() - 1), number));
    }
    values.push_back(v);
  }
  if (values.size() != 3) {
    throw ConfigError(fmt::format("{} '{}': give three angles, roll pitch yaw [deg]", option, text.substr(0, text.size() - 1)));
  }
  return {values[0], values[1], values[2]};
}

// Tr from a KITTI calib.txt (`Tr:` line) or from the per-sequence list
// (`NN: ...` lines), picking the sequence from the pose file's name (00.txt).
Pose load_velo_to_cam(const std::filesystem::path& calib, const std::filesystem::path& trajectory) {
  try {
    return read_velo_to_cam(calib);
  } catch (const InputError& first) {
    const std::string stem = trajectory.stem().string();
    const bool numeric = !stem.empty() && std::all_of(stem.begin(), stem.end(), [](unsigned char c) { return std::isdigit(c); });
    if (!numeric || !std::filesystem::is_regular_file(calib)) throw;
    // A sequence number of a few digits ("00".."21"); a longer name is no sequence.
    if (stem.size() > 6) throw;
    return read_velo_to_cam(calib, std::stoi(stem));
  }
}

/// The simulation the options ask for; defaults are SimulationOptions'.
SimulationOptions simulation_options(const SimulateArgs& args) {
  SimulationOptions options = args.sim;
  if (!args.trajectory.empty()) {
    if (!args.preset.empty()) throw ConfigError("give either --trajectory or --preset, not both");
    if (args.calib.empty()) throw ConfigError("--trajectory needs --calib (a KITTI calib.txt or calib_velo_to_cam.txt)");
    options.camera_poses = read_kitti_poses(args.trajectory);
    if (options.camera_poses.size() < 2) throw InputError(args.trajectory, "needs at least two poses");
    options.velo_to_cam = load_velo_to_cam(args.calib, args.trajectory);
    options.velo_to_cam_given = true;
  } else {
    if (!args.calib.empty()) throw ConfigError("--calib is only used with --trajectory");
    if (!args.preset.empty()) options.preset = args.preset;
  }
  const auto range = FrameRange::parse(args.frames);
  options.first_frame = range.first;
  options.end_frame = range.end;
  if (args.labels == "noisy") options.labels = LabelMode::kNoisy;
  if (args.labels == "gt") options.labels = LabelMode::kGroundTruth;
  if (!args.sensor.empty()) {
    if (options.beams != 64) throw ConfigError("give either --sensor or --beams (lasers of the HDL-64E), not both");
    options.sensor = sensor_profile(args.sensor);
    if (!args.azimuth_steps_given) options.azimuth_steps = options.sensor->simulation.azimuth_steps;
  }
  for (const auto& pass : args.passes) options.passes.push_back(parse_route_pass(pass));
  if (options.pass > 0 && options.passes.empty()) throw ConfigError("--pass needs --passes");
  options.mount_rpy_deg = rpy_option(args.mount_rpy, "--mount-rpy");
  options.cloud_frame_rpy_deg = rpy_option(args.cloud_frame_rpy, "--cloud-frame-rpy");
  options.skew = !args.no_skew;
  options.world.dynamic_objects = !args.no_dynamic;
  options.show_progress = spdlog::get_level() <= spdlog::level::info;
  return options;
}

/// The simulated frames written by sources/sequence_writer.hpp in another
/// layout (ring and time per point in PCD, PLY and bags; noisy labels
/// without their ground truth).
int write_in_layout(const SimulationOptions& options, const SimulateArgs& args) {
  SequenceWriteOptions layout;
  layout.format = *scan_format_from_name(args.format);
  const SimulatedSequence sequence(options);
  SimulatedSource source(sequence);
  write_scan_sequence(source, args.out, layout);
  std::cout << fmt::format("wrote {} frames as {} to {}\n", source.frames_rendered(), args.format, args.out);
  return 0;
}

/// The simulated frames as a Velodyne packet capture, OUT/velodyne.pcap
/// with its calibration OUT/velodyne.yaml (sources/velodyne_capture_writer.hpp).
int write_velodyne_pcap(const SimulationOptions& options, const SimulateArgs& args) {
  const SimulatedSequence sequence(options);
  SimulatedSource source(sequence);
  const LidarModel& lidar = sequence.lidar();
  const std::filesystem::path folder(args.out);
  std::error_code ec;
  if (std::filesystem::exists(folder, ec) && !std::filesystem::is_empty(folder, ec)) {
    throw InputError(folder, "exists and is not empty: a capture is written into a new or empty folder");
  }
  std::filesystem::create_directories(folder);
  const auto capture = folder / "velodyne.pcap";
  write_velodyne_capture(source, {lidar.elevation_deg, lidar.azimuth_steps, lidar.sweep_period}, capture);
  std::cout << fmt::format("wrote {} frames as a Velodyne {} capture to {} (calibration velodyne.yaml beside it)\n",
                           source.frames_rendered(), velodyne_model_name(velodyne_model_for(lidar.beams())),
                           capture.string());
  return 0;
}

int run_simulate(const SimulateArgs& args) {
  PathRules()
      .input("--trajectory", args.trajectory)
      .input("--calib", args.calib)
      .output("--out", args.out, OutputUse::kReplacedFolder)
      .check();
  const SimulationOptions options = simulation_options(args);
  const std::string source = args.trajectory.empty() ? "preset " + options.preset : args.trajectory;
  if (args.out.empty()) {
    if (!args.stats) throw ConfigError("--out is required (or --stats alone to measure the class shares)");
    spdlog::info("class shares of {} ({} beams, seed {}), rendered in memory", source, options.beams, options.seed);
    const SimulatedSequence sequence(options);
    std::cout << fmt::format("ground-truth class shares over {} frames:\n", sequence.size())
              << format_class_shares(measure_class_shares(sequence, options.show_progress));
    return 0;
  }
  spdlog::info("simulating {} ({}, seed {}, skew {}, labels {}) into {}", source,
               options.sensor ? options.sensor->title() : fmt::format("{} beams of the HDL-64E", options.beams),
               options.seed, options.skew ? "on" : "off", options.labels == LabelMode::kNoisy ? "noisy" : "gt", args.out);
  if (!options.imu.empty() && args.format != "semantickitti") {
    throw ConfigError("--imu writes imu.txt beside a SemanticKITTI-layout sequence: leave --format at semantickitti");
  }
  if (args.format == "velodyne-pcap") return write_velodyne_pcap(options, args);
  if (args.format != "semantickitti") return write_in_layout(options, args);
  const SimulationSummary s = simulate_sequence(options, args.out);
  if (args.stats) std::cout << "ground-truth class shares:\n" << format_class_shares(s.shares);
  std::cout << fmt::format("wrote {} frames, {} points ({:.0f} per frame) to {} in {:.1f} s ({:.2f} frames/s)\n", s.frames,
                           s.points, s.frames ? static_cast<double>(s.points) / static_cast<double>(s.frames) : 0.0, args.out,
                           s.seconds, s.seconds > 0 ? static_cast<double>(s.frames) / s.seconds : 0.0);
  if (options.labels == LabelMode::kNoisy && s.frames > 0) {
    std::cout << fmt::format("noisy labels: mIoU {:.1f} %, accuracy {:.1f} % (ground truth in labels_gt/)\n",
                             100.0 * s.miou, 100.0 * s.label_accuracy);
    for (int c = 1; c < kNumLearningClasses; ++c) {
      if (s.score.truth_count(c) == 0) continue;
      std::cout << fmt::format("  {:<14} IoU {:5.1f} %\n", learning_class_name(static_cast<std::uint8_t>(c)),
                               100.0 * s.score.iou(c));
    }
  }
  if (s.reseated_frames > 0) {
    spdlog::warn("the trajectory's height does not fit one ground surface at {} frames (up to {:.1f} m off): the sensor "
                 "was kept 1.2-2.5 m above the simulated ground there, so poses.txt (the trajectory as given) and the scans "
                 "disagree in height at those frames",
                 s.reseated_frames, s.max_sensor_offset);
  }
  if (s.interrupted) spdlog::warn("stopped after {} frames; the sequence written so far is complete and readable", s.frames);
  return 0;
}

const CommandRegistration kRegistration{Command{
    "simulate", "Write a synthetic sequence (ray-cast HDL-64E or a sensor profile in a procedural street world)", 10,
    [](CLI::App& app) {
      auto args = std::make_shared<SimulateArgs>();
      app.add_option("--out", args->out,
                     "Output sequence folder (velodyne/, labels/, poses.txt, calib.txt, times.txt); optional with --stats");
      app.add_option("--trajectory", args->trajectory, "KITTI ground-truth pose file (camera frame), e.g. poses/00.txt")
          ->check(CLI::ExistingFile);
      app.add_option("--calib", args->calib,
                     "KITTI calib.txt with a Tr: line, or a per-sequence list (NN: ...) picked by the pose file's name")
          ->check(CLI::ExistingFile);
      const auto names = preset_names();
      app.add_option("--preset", args->preset, fmt::format("Built-in route: {} (default {})", fmt::join(names, ", "), args->sim.preset))
          ->check(CLI::IsMember(names));
      app.add_option("--frames", args->frames, "Source frames A:B (B exclusive; A: or :B allowed)");
      app.add_option("--stride", args->sim.stride, "Use every K-th source pose (frames K x 0.1 s apart in times.txt; each sweep still lasts 0.1 s)")->check(CLI::Range(1, 100000));
      app.add_option("--seed", args->sim.seed, "World and noise seed");
      app.add_option("--passes", args->passes,
                     "Several drives through one world (route pose ranges A:B, A:B:reverse for the opposite lane "
                     "backwards), one after the other in time; --pass K renders the K-th (from 0), --frames within it. "
                     "simulation.yaml records where its first frame lies in the world (origin)")
          ->delimiter(',');
      app.add_option("--pass", args->sim.pass, "Which of --passes to render (from 0)");
      app.add_option("--labels", args->labels, "gt: exact labels; noisy: emulated network output in labels/, truth in labels_gt/")
          ->check(CLI::IsMember({"gt", "noisy"}));
      app.add_option("--beams", args->sim.beams, "Number of beams: 64 (HDL-64E), 32 or 16")->check(CLI::IsMember({64, 32, 16}));
      app.add_option("--sensor", args->sensor,
                     "Sensor profile to render: hdl64e, hdl32e, vlp16, os1-64, os1-128 (config/sensors/) or a profile "
                     "file; default the HDL-64E (--beams)");
      app.add_option("--format", args->format,
                     "Layout to write: semantickitti (default), pcd, ply, kitti-raw, rosbag, rosbag2, mcap (PCD, PLY and "
                     "bags keep each point's ring and time), velodyne-pcap (OUT/velodyne.pcap: the sensor's packets, "
                     "VLP-16, HDL-32E or HDL-64E by the lasers, with OUT/velodyne.yaml, its calibration)")
          ->check(CLI::IsMember({"semantickitti", "pcd", "ply", "kitti-raw", "rosbag", "rosbag2", "mcap", "velodyne-pcap"}));
      app.add_option("--azimuth-steps", args->sim.azimuth_steps,
                     "Columns per turn (HDL-64E: about 2083; with --sensor the profile's)")
          ->check(CLI::Range(16, 8000))
          ->each([args](const std::string&) { args->azimuth_steps_given = true; });
      app.add_option("--mount-rpy", args->mount_rpy,
                     "The sensor tilted on the vehicle: roll pitch yaw [deg] (R_vehicle<-sensor, URDF rpy; \"0 20 0\": "
                     "the front looks down 20 deg); scans in the sensor's frame, Tr in calib.txt to the level camera")
          ->expected(1, 3);
      app.add_option("--cloud-frame-rpy", args->cloud_frame_rpy,
                     "The scans written in a frame turned against the sensor's: roll pitch yaw [deg] (R_cloud<-sensor), "
                     "as a driver publishing in a robot's base link; Tr in calib.txt follows")
          ->expected(1, 3);
      app.add_option("--imu", args->sim.imu,
                     "An IMU riding in the sensor, written as OUT/imu.txt (time, specific force, angular velocity in the "
                     "scans' frame): icm-20948 (inside Ouster sensors, 100 Hz) or adis16465 (400 Hz), with their noise "
                     "and biases; needs motion within sweeps (--preset handheld-walk)")
          ->check(CLI::IsMember(imu_model_names()));
      app.add_flag("--no-skew", args->no_skew, "Take each scan at one instant (no motion distortion)");
      app.add_flag("--no-dynamic", args->no_dynamic, "No moving cars or pedestrians");
      app.add_flag("--stats", args->stats,
                   "Print the ground-truth class shares against SemanticKITTI's; without --out, only measure them (nothing written)");
      return [args] { return run_simulate(*args); };
    }}};

}  // namespace
}  // namespace saloam::cli
