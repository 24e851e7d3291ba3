#include "saloam/sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/imu_text.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/sim/simulation_record.hpp"
#include "saloam/sim/trajectories.hpp"

namespace fs = std::filesystem;

namespace saloam {

Pose output_velo_to_cam(const SimulationOptions& options) {
  return options.velo_to_cam_given ? options.velo_to_cam : kitti_velo_to_cam();
}

namespace {
/// The trajectory's LiDAR poses moved to the sensor's mount: `dz` [m] along
/// each pose's up axis (a sensor mounted lower than KITTI's rides below it).
std::vector<Pose> mounted(std::vector<Pose> poses, double dz) {
  if (dz == 0.0) return poses;
  for (Pose& T : poses) T = T * Eigen::Translation3d(0.0, 0.0, dz);
  return poses;
}
}  // namespace

double sensor_mount_height(const SimulationOptions& options) {
  return options.sensor ? options.sensor->simulation.mount_height : options.world.sensor_height;
}

namespace {
/// [m] the sensor rides this far above (below: negative) KITTI's mount along
/// each pose's up axis.
double mount_offset(const SimulationOptions& options) {
  return sensor_mount_height(options) - options.world.sensor_height;
}
}  // namespace

RoutePass parse_route_pass(std::string_view text) {
  const std::string t(text);
  const auto bad = [&] {
    return ConfigError(fmt::format("pass '{}': use FIRST:END or FIRST:END:reverse (route pose indices, END may be empty)", t));
  };
  RoutePass pass;
  std::string_view rest = text;
  const auto first_colon = rest.find(':');
  if (first_colon == std::string_view::npos) throw bad();
  const std::string_view first = rest.substr(0, first_colon);
  rest = rest.substr(first_colon + 1);
  const auto second_colon = rest.find(':');
  const std::string_view end = rest.substr(0, second_colon);
  if (second_colon != std::string_view::npos) {
    const std::string_view flag = rest.substr(second_colon + 1);
    if (flag != "reverse" && flag != "r") throw bad();
    pass.reverse = true;
  }
  const auto number = [&](std::string_view s, std::size_t& out) {
    if (s.empty() || s.size() > 12 || s.find_first_not_of("0123456789") != std::string_view::npos) throw bad();
    out = static_cast<std::size_t>(std::stoull(std::string(s)));
  };
  number(first, pass.first);
  if (!end.empty()) number(end, pass.end);
  if (pass.end <= pass.first) throw bad();
  return pass;
}

std::string route_pass_text(const RoutePass& pass) {
  return fmt::format("{}:{}{}", pass.first,
                     pass.end == std::numeric_limits<std::size_t>::max() ? std::string() : std::to_string(pass.end),
                     pass.reverse ? ":reverse" : "");
}

namespace {
// A step between consecutive trajectory poses longer than this [m] (180
// km/h at 10 Hz) is the jump from one pass to the next, never driven.
constexpr double kPassJump = 5.0;

/// The passes one after the other: each a stretch of the route, a reverse
/// one driven backwards in the opposite lane (kReversePassLane to the left
/// of the route, heading turned by 180 degrees).
std::vector<Pose> concatenated_passes(const std::vector<Pose>& route, const std::vector<RoutePass>& passes) {
  std::vector<Pose> out;
  for (const RoutePass& pass : passes) {
    const std::size_t end = std::min(pass.end, route.size());
    if (pass.first + 1 >= end) {
      throw ConfigError(fmt::format("pass {} selects fewer than 2 of the route's {} poses", route_pass_text(pass), route.size()));
    }
    std::vector<Pose> stretch(route.begin() + static_cast<std::ptrdiff_t>(pass.first),
                              route.begin() + static_cast<std::ptrdiff_t>(end));
    if (pass.reverse) {
      std::reverse(stretch.begin(), stretch.end());
      for (Pose& T : stretch) {
        T = T * Eigen::Translation3d(0.0, kReversePassLane, 0.0) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ());
        T = orthonormalized(T);
      }
    }
    out.insert(out.end(), stretch.begin(), stretch.end());
  }
  return out;
}

/// First trajectory index of each pass, and the total.
std::vector<std::size_t> pass_offsets(const std::vector<RoutePass>& passes, std::size_t route_size) {
  std::vector<std::size_t> offsets{0};
  for (const RoutePass& pass : passes) offsets.push_back(offsets.back() + std::min(pass.end, route_size) - pass.first);
  return offsets;
}

std::vector<Pose> route_trajectory(const SimulationOptions& options) {
  if (!options.camera_poses.empty()) {
    if (!options.velo_to_cam_given) throw ConfigError("a camera-frame trajectory needs its velodyne-to-camera Tr");
    return camera_to_lidar_poses(options.camera_poses, options.velo_to_cam);
  }
  return preset_trajectory(options.preset, options.frame_period);
}
}  // namespace

std::vector<Pose> source_lidar_trajectory(const SimulationOptions& options) {
  const double dz = mount_offset(options);
  std::vector<Pose> route = route_trajectory(options);
  if (!options.passes.empty()) {
    if (options.pass >= options.passes.size()) {
      throw ConfigError(fmt::format("pass {} of {} passes (passes count from 0)", options.pass, options.passes.size()));
    }
    route = concatenated_passes(route, options.passes);
  }
  return mounted(std::move(route), dz);
}

std::vector<std::size_t> selected_frames(const SimulationOptions& options, std::size_t trajectory_size) {
  if (options.stride == 0) throw ConfigError("stride must be at least 1");
  std::size_t offset = 0;
  if (!options.passes.empty()) {
    // Frames count within the rendered pass.
    const std::size_t route_size = route_trajectory(options).size();
    const std::vector<std::size_t> offsets = pass_offsets(options.passes, route_size);
    if (options.pass >= options.passes.size() || offsets.back() != trajectory_size) {
      throw ConfigError(fmt::format("pass {} of {} passes (passes count from 0)", options.pass, options.passes.size()));
    }
    offset = offsets[options.pass];
    trajectory_size = offsets[options.pass + 1] - offset;
  }
  const std::size_t end = std::min(options.end_frame, trajectory_size);
  if (options.first_frame >= end) {
    throw ConfigError(fmt::format("frame range {}:{} selects nothing (the trajectory has {} poses)", options.first_frame,
                                  options.end_frame == std::numeric_limits<std::size_t>::max() ? std::string{}
                                                                                                : std::to_string(options.end_frame),
                                  trajectory_size));
  }
  std::vector<std::size_t> frames;
  for (std::size_t i = options.first_frame; i < end; i += options.stride) frames.push_back(offset + i);
  return frames;
}

SweepSpec sweep_for_frame(const std::vector<Pose>& traj, std::size_t i, const SimulationOptions& options) {
  SweepSpec s;
  s.start = traj.at(i);
  const double period = options.frame_period;
  // The sweep lasts one frame period whatever the stride: the sensor moves
  // from pose i towards pose i+1 while it turns.
  const auto jump = [&](std::size_t a) { return (traj[a + 1].translation() - traj[a].translation()).norm() > kPassJump; };
  if (i + 1 < traj.size() && !jump(i)) {
    s.end = traj[i + 1];
  } else if (i >= 1 && !jump(i - 1)) {  // last pose (of the route or of a pass): continue the previous motion
    s.end = orthonormalized(traj[i] * (traj[i - 1].inverse() * traj[i]));
  } else {
    s.end = traj[i];
  }
  s.time_start = static_cast<double>(i) * period;
  s.time_end = static_cast<double>(i + 1) * period;
  s.seed = hash3(options.seed, 0xf7a3ull, i);
  s.skew = options.skew;
  return s;
}

namespace {

LidarModel lidar_for(const SimulationOptions& options) {
  if (options.sensor && options.beams != 64) {
    throw ConfigError("beams picks lasers of the HDL-64E: with a sensor profile, leave it at 64");
  }
  LidarModel lidar = options.sensor ? LidarModel::from_profile(*options.sensor) : LidarModel::hdl64e(options.beams);
  if (options.azimuth_steps < 16) throw ConfigError("azimuth steps must be at least 16");
  lidar.azimuth_steps = options.azimuth_steps;
  lidar.sweep_period = options.frame_period;
  return lidar;
}

// The world is built along the trajectory, or along a preset's own track
// (the handheld walk's path, without its gait and look-arounds).
World world_for(const std::vector<Pose>& trajectory, const SimulationOptions& options) {
  WorldOptions world_options = options.world;
  world_options.frame_period = options.frame_period;
  world_options.sensor_height = sensor_mount_height(options);
  if (!options.camera_poses.empty()) return build_world(trajectory, options.seed, world_options);
  if (preset_on_hillside(options.preset)) world_options.hillside = true;
  const double dz = mount_offset(options);
  const std::vector<Pose> track = preset_motion(options.preset) ? mounted(preset_track(options.preset, options.frame_period), dz)
                                                                : trajectory;
  return build_world(track, options.seed, world_options);
}

// A preset's motion within sweeps at the sensor's mount height; empty for
// trajectories that are linear between frames.
ContinuousMotion continuous_motion(const SimulationOptions& options) {
  if (!options.camera_poses.empty()) return {};
  ContinuousMotion motion = preset_motion(options.preset);
  if (!motion) return {};
  if (!options.passes.empty()) throw ConfigError(fmt::format("the {} preset is walked once: it takes no passes", options.preset));
  const double dz = mount_offset(options);
  return [motion = std::move(motion), dz](double t) { return Pose(motion(t) * Eigen::Translation3d(0.0, 0.0, dz)); };
}

// An IMU is simulated from motion within sweeps: ConfigError for a
// trajectory without.
void require_imu_motion(const ContinuousMotion& motion) {
  if (!motion) {
    throw ConfigError("an IMU needs a trajectory with motion within sweeps (--preset handheld-walk): the driving presets "
                      "and given trajectories are linear between frames");
  }
}

// Knots of a sweep with continuous motion: 20 steps per sweep (5 ms at 10 Hz).
constexpr int kSweepKnots = 21;

}  // namespace

SimulatedSequence::SimulatedSequence(const SimulationOptions& options)
    : options_(options),
      trajectory_(source_lidar_trajectory(options)),
      motion_(continuous_motion(options)),
      frames_(selected_frames(options, trajectory_.size())),
      mount_(rotation_from_rpy_deg(options.mount_rpy_deg)),
      cloud_frame_(rotation_from_rpy_deg(options.cloud_frame_rpy_deg)),
      lidar_(lidar_for(options)),
      rays_(lidar_, mount_),
      world_(world_for(trajectory_, options)),
      // The scans' frame to the camera: camera <- vehicle's lidar <- sensor <- scans.
      velo_to_cam_(orthonormalized(output_velo_to_cam(options) * Pose(mount_ * cloud_frame_.transpose()))) {
  if (!options.mount_rpy_deg.allFinite() || !options.cloud_frame_rpy_deg.allFinite()) {
    throw ConfigError("the mount's and the cloud frame's roll, pitch and yaw must be finite numbers [deg]");
  }
  if (!options.imu.empty()) {  // refused before anything is written
    (void)imu_model(options.imu);
    require_imu_motion(motion_);
  }
  // poses.txt is the vehicle's camera, whatever the sensor's tilt.
  const Pose vehicle_to_cam = output_velo_to_cam(options);
  // Re-based so that the first selected frame is the origin.
  const Pose base_inv = trajectory_[frames_.front()].inverse();
  std::vector<Pose> lidar_out, sensor_out;
  for (const std::size_t i : frames_) {
    lidar_out.push_back(orthonormalized(base_inv * trajectory_[i]));
    // Where the sweep really started: the given pose, raised or lowered onto
    // the ground where the trajectory's heights do not fit one surface.
    Pose sensor = trajectory_[i];
    sensor.translation() = world_.sensor_origin(sensor.translation());
    sensor_out.push_back(orthonormalized(base_inv * sensor));
    times_.push_back(static_cast<double>(i - frames_.front()) * options.frame_period);
  }
  camera_poses_ = lidar_to_camera_poses(lidar_out, vehicle_to_cam);
  sensor_camera_poses_ = lidar_to_camera_poses(sensor_out, vehicle_to_cam);
}

Eigen::Vector3d SimulatedSequence::first_scan_up() const {
  // The vehicle's lidar frame at the first frame in the route's world (z up).
  const Eigen::Matrix3d world_from_scan = trajectory_[frames_.front()].linear() * mount_ * cloud_frame_.transpose();
  return world_from_scan.transpose() * Eigen::Vector3d::UnitZ();
}

SimulatedImu SimulatedSequence::imu(const ImuNoise& noise, bool noisy) const {
  require_imu_motion(motion_);
  // The sensor's motion in the route's world; the samples turned into the
  // scans' frame and put on times.txt's clock.
  const Eigen::Matrix3d mount = mount_;
  const ContinuousMotion sensor = [this, mount](double t) { return Pose(motion_(t) * Pose(mount)); };
  const double start = static_cast<double>(frames_.front()) * options_.frame_period;
  const double end = static_cast<double>(frames_.back() + 1) * options_.frame_period;
  SimulatedImu out = simulate_imu(sensor, start, end, noise, hash_combine(options_.seed, 0x1a3ull), noisy);
  for (ImuSample& sample : out.samples) {
    sample.time -= start;
    sample.acceleration = cloud_frame_ * sample.acceleration;
    sample.angular_velocity = cloud_frame_ * sample.angular_velocity;
  }
  out.gyro_bias = cloud_frame_ * out.gyro_bias;
  out.accel_bias = cloud_frame_ * out.accel_bias;
  return out;
}

SimulatedFrame SimulatedSequence::render(std::size_t k) const {
  SweepSpec sweep = sweep_for_frame(trajectory_, frames_.at(k), options_);
  if (motion_) {
    for (int j = 0; j < kSweepKnots; ++j) {
      const double f = static_cast<double>(j) / (kSweepKnots - 1);
      sweep.knots.push_back(motion_(sweep.time_start + f * (sweep.time_end - sweep.time_start)) * Pose(mount_));
    }
  }
  sweep.start = sweep.start * Pose(mount_);
  sweep.end = sweep.end * Pose(mount_);
  SimulatedScan scan = simulate_scan(world_, lidar_, rays_, sweep);
  if (scan.cloud.size() == 0) {
    const Eigen::Vector3d p = sweep.start.translation();
    throw std::runtime_error(fmt::format("simulated frame {} (source pose {}, sensor at {:.2f} {:.2f} {:.2f}) has no points",
                                         k, frames_[k], p.x(), p.y(), p.z()));
  }
  SimulatedFrame frame;
  frame.sensor_offset = scan.sensor_offset;
  if (options_.labels == LabelMode::kNoisy) {
    frame.gt_labels = scan.cloud.label;
    frame.gt_instances = scan.cloud.instance;
    scan.cloud.label = emulate_segmentation(scan, lidar_.beams(), lidar_.azimuth_steps,
                                            hash_combine(sweep.seed, 0x9e7ull), options_.label_noise);
    std::fill(scan.cloud.instance.begin(), scan.cloud.instance.end(), 0);
  }
  frame.cloud = std::move(scan.cloud);
  if (!cloud_frame_.isIdentity()) {
    const Eigen::Matrix3f R = cloud_frame_.cast<float>();
    for (Eigen::Vector3f& p : frame.cloud.points) p = R * p;
  }
  return frame;
}

SimulationSummary simulate_sequence(const SimulationOptions& options, const fs::path& out_dir) {
  const StageTimer timer;
  const SimulatedSequence sequence(options);
  OutputFolder folder = open_sequence_output(out_dir);
  SequenceWriter writer(out_dir);
  write_simulation_record(out_dir, options);
  writer.write_calib(sequence.velo_to_cam());
  // Written up front so that a crash mid-way still leaves a readable sequence
  // (the reader accepts more poses than scans); trimmed on interruption.
  writer.write_camera_poses(sequence.camera_poses());
  writer.write_times(sequence.times());
  if (!options.imu.empty()) {
    const ImuNoise noise = imu_model(options.imu);
    write_imu_text(out_dir / "imu.txt", sequence.imu(noise).samples,
                   fmt::format("simulated {} at {:g} Hz in the scans' frame (saloam simulate --imu {})", noise.name,
                               noise.rate_hz, noise.name));
  }
  const bool noisy = options.labels == LabelMode::kNoisy;
  if (noisy) create_folder(out_dir / "labels_gt");

  SimulationSummary summary;
  ProgressBar progress(sequence.size(), "simulate", options.show_progress);
  for (std::size_t k = 0; k < sequence.size(); ++k) {
    if (stop_requested()) {
      summary.interrupted = true;
      break;
    }
    SimulatedFrame frame = sequence.render(k);
    const double offset = std::abs(static_cast<double>(frame.sensor_offset));
    summary.max_sensor_offset = std::max(summary.max_sensor_offset, offset);
    if (offset > 0.0) ++summary.reseated_frames;
    summary.shares.add(noisy ? frame.gt_labels : frame.cloud.label);
    if (noisy) {
      summary.score.add(frame.gt_labels, frame.cloud.label);
      write_scan_labels(out_dir / "labels_gt" / (frame_name(k) + ".label"), frame.gt_labels, frame.gt_instances);
    }
    writer.write_scan(k, frame.cloud);
    summary.points += frame.cloud.size();
    ++summary.frames;
    progress.advance();
  }
  progress.finish();
  const auto first = [&](const auto& all) {
    return std::vector(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(summary.frames));
  };
  if (summary.frames < sequence.size()) {
    writer.write_camera_poses(first(sequence.camera_poses()));
    writer.write_times(first(sequence.times()));
  }
  if (summary.reseated_frames > 0) write_kitti_poses(out_dir / "poses_sensor.txt", first(sequence.sensor_camera_poses()));
  if (noisy && summary.frames > 0) {
    summary.miou = summary.score.miou();
    summary.label_accuracy = summary.score.accuracy();
  }
  summary.seconds = timer.elapsed_s();
  folder.finish(summary.interrupted ? "interrupted" : "complete");
  return summary;
}

}  // namespace saloam
