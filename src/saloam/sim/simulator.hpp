#pragma once
// Synthetic SemanticKITTI sequences: a trajectory (preset or KITTI poses),
// a world built along it, one simulated sweep per frame (the HDL-64E, or a
// sensor profile's LiDAR), written in
// the SemanticKITTI layout so every other command reads it like real data:
//   velodyne/NNNNNN.bin  labels/NNNNNN.label  [labels_gt/NNNNNN.label]
//   poses.txt (camera frame, P_i = Tr Q_i Tr^-1, P_0 = I)  calib.txt (Tr)  times.txt (s; 10 Hz sensor)
//   poses_sensor.txt, only where a trajectory's heights do not fit one ground
//     surface (the simulator then rides the sensor on the ground): where each
//     sweep really started, in poses.txt's frame. poses.txt stays the
//     trajectory as given, height errors included, as KITTI's ground truth;
//     poses_sensor.txt is the truth of the scans (e.g. to judge loop closures).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/sensor_profile.hpp"
#include "saloam/core/types.hpp"
#include "saloam/eval/segmentation_score.hpp"
#include "saloam/imu/imu_noise.hpp"
#include "saloam/sim/class_shares.hpp"
#include "saloam/sim/imu_simulation.hpp"
#include "saloam/sim/lidar.hpp"
#include "saloam/sim/label_noise.hpp"
#include "saloam/sim/trajectories.hpp"
#include "saloam/sim/world.hpp"

namespace saloam {

enum class LabelMode { kGroundTruth, kNoisy };

/// One drive through the route's world (SimulationOptions::passes): route
/// poses [first, end), driven backwards in the opposite lane when `reverse`.
struct RoutePass {
  std::size_t first = 0;
  std::size_t end = std::numeric_limits<std::size_t>::max();
  bool reverse = false;
};
/// "A:B" or "A:B:reverse" (B may be empty: to the route's end); ConfigError otherwise.
RoutePass parse_route_pass(std::string_view text);
std::string route_pass_text(const RoutePass& pass);
/// [m] to the left of the route a reverse pass drives (the oncoming lane).
inline constexpr double kReversePassLane = 3.2;

struct SimulationOptions {
  /// Built-in route, used when `camera_poses` is empty (see preset_names()).
  std::string preset = "urban-loop";
  /// A KITTI ground-truth trajectory P_i (camera frame) with its Tr.
  std::vector<Pose> camera_poses;
  Pose velo_to_cam = Pose::Identity();  ///< Tr; presets use KITTI 00's when left identity
  bool velo_to_cam_given = false;
  /// Source frames [first_frame, end_frame) every `stride`-th; renumbered from
  /// 0. times.txt keeps the true times (stride K: frames K * 0.1 s apart), so
  /// the motion within a sweep stays that of a real 10 Hz sensor.
  std::size_t first_frame = 0;
  std::size_t end_frame = std::numeric_limits<std::size_t>::max();
  std::size_t stride = 1;
  std::uint64_t seed = 1;
  /// Several drives through one world (sessions of a map): the
  /// world is built along all of them, one after the other in time (so other
  /// moving objects, parked cars, label noise and sensor noise meet each),
  /// and `pass` is rendered; first_frame, end_frame and stride then count
  /// within that pass. Empty: the route once, as it is.
  std::vector<RoutePass> passes;
  std::size_t pass = 0;
  LabelMode labels = LabelMode::kGroundTruth;
  /// Lasers of the HDL-64E: all 64, or every 2nd (32) or 4th (16): the same
  /// sensor thinned out (--beams); 64 with a sensor profile.
  int beams = 64;
  /// A sensor profile rendered instead of the HDL-64E (--sensor): its lasers,
  /// ranges, noise, car body and mount height (the trajectory, a car's
  /// LiDAR at world.sensor_height, is moved down or up to it).
  std::optional<SensorProfile> sensor;
  /// Firing positions per turn (the CLI takes a profile's
  /// simulation.azimuth_steps unless --azimuth-steps is given).
  int azimuth_steps = 2083;
  /// The sensor's tilt on the vehicle, R_vehicle<-sensor as roll, pitch, yaw
  /// [deg] (URDF rpy; pitch 20: the front looks down 20 deg): its rays and
  /// the car body it sees turn with it. The scans are in its own frame;
  /// calib.txt's Tr maps them to the (level) camera, poses.txt is the
  /// vehicle's motion as without a tilt.
  Eigen::Vector3d mount_rpy_deg = Eigen::Vector3d::Zero();
  /// The frame the scans are written in, R_cloud<-sensor as roll, pitch, yaw
  /// [deg]: the same scans handed over in a turned frame (as a driver that
  /// publishes in a robot's base link). Only the points turn; Tr follows.
  Eigen::Vector3d cloud_frame_rpy_deg = Eigen::Vector3d::Zero();
  /// An IMU model (imu_model_names()) riding in the sensor, written as
  /// imu.txt in the scans' frame (io/imu_text.hpp); empty: none. Needs a
  /// trajectory with motion within sweeps (the handheld walk).
  std::string imu;
  bool skew = true;
  bool show_progress = true;
  double frame_period = 0.1;
  WorldOptions world;
  LabelNoiseOptions label_noise;
};

struct SimulationSummary {
  std::size_t frames = 0;          ///< frames written
  std::size_t points = 0;          ///< total points written
  double seconds = 0;              ///< wall time of the ray casting and writing
  double miou = std::numeric_limits<double>::quiet_NaN();  ///< noisy labels vs truth
  double label_accuracy = std::numeric_limits<double>::quiet_NaN();
  SegmentationScore score;         ///< per-class IoU of the noisy labels
  ClassShares shares;              ///< ground-truth class shares of the frames written
  bool interrupted = false;
  /// Frames where the sensor had to leave the trajectory's height to stay on
  /// the ground (inconsistent ground-truth heights), and the largest offset [m].
  std::size_t reseated_frames = 0;
  double max_sensor_offset = 0;
};

/// Height of the simulated sensor above the road [m]: the profile's mount,
/// else world.sensor_height (KITTI's 1.73 m).
double sensor_mount_height(const SimulationOptions& options);
/// The whole source trajectory in the LiDAR frame, Q_i = T_L0<-Li, at the
/// sensor's mount height.
std::vector<Pose> source_lidar_trajectory(const SimulationOptions& options);
/// Tr used for the output (KITTI 00's for presets unless given).
Pose output_velo_to_cam(const SimulationOptions& options);
/// Source indices of the frames to simulate. Throws ConfigError on an empty selection.
std::vector<std::size_t> selected_frames(const SimulationOptions& options, std::size_t trajectory_size);

/// Sweep of the frame with source index `i`: from pose i towards pose i+1
/// over one frame period (world time i * frame_period).
SweepSpec sweep_for_frame(const std::vector<Pose>& lidar_trajectory, std::size_t source_index,
                          const SimulationOptions& options);

/// One simulated frame: the scan (labels as chosen: noisy or ground truth)
/// and, with noisy labels, the ground-truth labels beside them.
struct SimulatedFrame {
  LabelledCloud cloud;
  /// With noisy labels, the ground truth (class, instance id); empty otherwise.
  std::vector<std::uint16_t> gt_labels, gt_instances;
  float sensor_offset = 0;               ///< see SimulatedScan::sensor_offset
};

/// A simulated sequence held in memory: trajectory, world and sensor are set
/// up once; frames are rendered on request, in any order, each a pure
/// function of its index (so a sequence written to disk and one streamed
/// frame by frame are the same). Poses follow the sequence layout above:
/// re-based on the first selected frame, camera frame, times from 0.
class SimulatedSequence {
 public:
  /// Throws ConfigError on invalid options (empty selection, bad beam count, ...).
  explicit SimulatedSequence(const SimulationOptions& options);
  SimulatedSequence(const SimulatedSequence&) = delete;
  SimulatedSequence& operator=(const SimulatedSequence&) = delete;

  [[nodiscard]] std::size_t size() const { return frames_.size(); }
  [[nodiscard]] const SimulationOptions& options() const { return options_; }
  /// Renders frame k (k < size()). Throws std::runtime_error when the frame
  /// has no return at all (never an empty scan). Thread-safe.
  [[nodiscard]] SimulatedFrame render(std::size_t k) const;

  [[nodiscard]] const Pose& velo_to_cam() const { return velo_to_cam_; }
  /// The sensor the sweeps are rendered with.
  [[nodiscard]] const LidarModel& lidar() const { return lidar_; }
  [[nodiscard]] const std::vector<Pose>& camera_poses() const { return camera_poses_; }  ///< poses.txt
  [[nodiscard]] const std::vector<double>& times() const { return times_; }              ///< times.txt [s]
  /// LiDAR pose of the first frame in the world frame (the frame of the
  /// route's first pose): the poses are re-based on it, so two passes of one
  /// world are related by origin_a^-1 * origin_b (T_a0<-b0).
  [[nodiscard]] const Pose& origin() const { return trajectory_[frames_.front()]; }
  /// Where each sweep really started (poses_sensor.txt's content, camera frame).
  [[nodiscard]] const std::vector<Pose>& sensor_camera_poses() const { return sensor_camera_poses_; }
  /// Up in the written scans' frame at the first frame (against gravity).
  [[nodiscard]] Eigen::Vector3d first_scan_up() const;
  /// The IMU riding in the sensor over every sweep, in the written scans'
  /// frame, times on times.txt's clock (sim/imu_simulation.hpp). ConfigError
  /// when the trajectory is linear between frames (no motion to measure
  /// within them: the driving presets, a given trajectory).
  [[nodiscard]] SimulatedImu imu(const ImuNoise& noise, bool noisy = true) const;

 private:
  SimulationOptions options_;
  std::vector<Pose> trajectory_;  ///< source trajectory, LiDAR frame
  /// The preset's motion within sweeps (the handheld walk), at the sensor's
  /// mount height; empty: linear between trajectory_'s poses.
  ContinuousMotion motion_;
  std::vector<std::size_t> frames_;
  Eigen::Matrix3d mount_;        ///< R_vehicle<-sensor
  Eigen::Matrix3d cloud_frame_;  ///< R_cloud<-sensor
  LidarModel lidar_;
  SweepRays rays_;
  World world_;
  Pose velo_to_cam_ = Pose::Identity();
  std::vector<Pose> camera_poses_, sensor_camera_poses_;
  std::vector<double> times_;
};

/// Simulates and writes the sequence to `out_dir` (created). Stops cleanly on
/// stop_requested(): the frames written so far form a valid sequence. A frame
/// without any return is an error (std::runtime_error naming the frame), never
/// an empty scan file.
SimulationSummary simulate_sequence(const SimulationOptions& options, const std::filesystem::path& out_dir);

}  // namespace saloam
