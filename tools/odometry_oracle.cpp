// odometry_oracle: the systematic error a simulated sequence's features carry
// on their own, without the odometry's drift. Every scan is de-skewed with
// its ground-truth motion and registered to a local map built from the
// ground-truth poses (the odometry's features, voxels and registration,
// `--set` as for `saloam odom`), starting at its ground-truth pose: the mean
// offset of the registered poses from the ground truth is the bias the
// features pull with (forward, left, up [mm per frame] in the sensor frame,
// which along a straight road are the route's forward, lateral and vertical
// directions). The odometry chains such offsets, partly held back by the map
// points it keeps from earlier frames. `--drop` leaves out the features of
// classes (SemanticKITTI training class indices, after class grouping): the
// change of the offset is what those classes pull with.
//
// With `--trajectory` (the KITTI poses the sequence was simulated along, and
// its world seed) it also compares every pole and trunk edge feature with the
// axis of the simulator's cylinder it lies on: mean error along the sensor's
// ray and across it, by range.
//
//   odometry_oracle SEQ [--labels DIR] [--no-semantics] [--frames A:B] [--drop 16,18] [--set k=v]
//                   [--trajectory poses/08.txt --seed 1]

#include <array>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "saloam/core/config.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/calibration.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/odometry/deskew.hpp"
#include "saloam/odometry/features.hpp"
#include "saloam/odometry/local_map.hpp"
#include "saloam/odometry/registration.hpp"
#include "saloam/sim/simulator.hpp"
#include "saloam/sim/world.hpp"

namespace saloam {
namespace {

struct OracleOptions {
  std::string sequence;
  std::string labels;
  bool no_semantics = false;
  std::string frames;
  std::vector<int> drop;
  std::vector<std::string> set;
  std::string trajectory;
  std::uint64_t seed = 1;
};

/// Where the scans were taken, as LiDAR poses at sweep start: poses_sensor.txt
/// when the simulator wrote one, else poses.txt.
std::vector<Pose> sensor_poses(const std::filesystem::path& dir, const SequenceReader& reader) {
  if (std::filesystem::exists(dir / "poses_sensor.txt")) {
    return camera_to_lidar_poses(read_kitti_poses(dir / "poses_sensor.txt"), reader.velo_to_cam());
  }
  return reader.lidar_poses();
}

/// Mid-sweep pose of scan k (the odometry registers at mid-sweep): halfway
/// along the motion to the next sweep start.
Pose mid_sweep(const std::vector<Pose>& start, std::size_t k) {
  const std::size_t a = k + 1 < start.size() ? k : k - 1;
  return start[k] * se3_exp(0.5 * se3_log(start[a].inverse() * start[a + 1]));
}

ScanFeatures features_of(const LabelledCloud& cloud, const OdometryConfig& config, const ClassVoxelSizes& voxels,
                         const std::set<int>& drop) {
  const bool use_labels = config.use_semantics && cloud.has_labels;
  ScanFeatures f = extract_features(cloud, config.features, use_labels, false);
  for (FeatureCloud* part : {&f.edges, &f.planars}) {
    FeatureCloud kept;
    for (std::size_t i = 0; i < part->size(); ++i) {
      const ClassIndex c = use_labels && config.match_class_groups ? class_group(part->classes[i]) : part->classes[i];
      if (!drop.contains(c)) kept.push_back(part->points[i], c, part->sweep_time[i]);
    }
    *part = voxel_downsample(kept, voxels);
  }
  return f;
}

/// Errors of pole and trunk edge features against the simulator's cylinder axes.
class AxisErrors {
 public:
  AxisErrors(const OracleOptions& o, const Pose& velo_to_cam) {
    SimulationOptions sim;
    sim.camera_poses = read_kitti_poses(o.trajectory);
    sim.velo_to_cam = velo_to_cam;
    sim.velo_to_cam_given = true;
    sim.seed = o.seed;
    WorldOptions world_options = sim.world;
    world_options.frame_period = sim.frame_period;
    const World world = build_world(source_lidar_trajectory(sim), sim.seed, world_options);
    for (const auto& p : world.primitives()) {
      if (p.shape == Shape::kCylinder && is_thin_round(p.label)) cylinders_.push_back(p);
    }
  }

  /// `edges` in the sensor frame, `world_from_sensor` the ground-truth pose.
  void add(const FeatureCloud& edges, const Pose& world_from_sensor) {
    for (std::size_t i = 0; i < edges.size(); ++i) {
      const std::uint16_t label = from_learning_class(edges.classes[i]);
      if (!is_thin_round(label)) continue;
      const Eigen::Vector3d world = world_from_sensor * edges.points[i];
      const Primitive* axis = nearest_cylinder(world);
      if (!axis) continue;
      const Eigen::Vector3d error =
          world_from_sensor.linear().transpose() *
          Eigen::Vector3d(world.x() - axis->center.x(), world.y() - axis->center.y(), 0.0);
      const Eigen::Vector2d ray = edges.points[i].head<2>().normalized();
      const double range = edges.points[i].head<2>().norm();
      const std::size_t bin = range < 10 ? 0 : range < 20 ? 1 : range < 30 ? 2 : 3;
      auto& sum = sums_[label == cls::kTrunk][bin];
      sum[0] += error.head<2>().dot(ray);
      sum[1] += std::abs(error.head<2>().dot(Eigen::Vector2d(-ray.y(), ray.x())));
      sum[2] += 1;
    }
  }

  void print() const {
    std::printf("\naxis error of pole and trunk edge features [mm]: mean along the ray (+: beyond the axis) | mean |across|\n");
    static constexpr std::array<const char*, 4> kBins{"< 10 m", "10-20 m", "20-30 m", ">= 30 m"};
    for (int object = 0; object < 2; ++object) {
      for (std::size_t b = 0; b < kBins.size(); ++b) {
        const auto& s = sums_[static_cast<std::size_t>(object)][b];
        if (s[2] == 0) continue;
        std::printf("%-5s %-8s along %+7.1f | across %6.1f  (%.0f features)\n", object ? "trunk" : "pole", kBins[b],
                    1e3 * s[0] / s[2], 1e3 * s[1] / s[2], s[2]);
      }
    }
  }

 private:
  const Primitive* nearest_cylinder(const Eigen::Vector3d& p) const {
    const Primitive* best = nullptr;
    double best_distance = 0.6;  // [m] farther than any radius and estimate error
    for (const auto& c : cylinders_) {
      const double d = Eigen::Vector2d(p.x() - c.center.x(), p.y() - c.center.y()).norm();
      if (d < best_distance && p.z() > c.z_min - 0.5 && p.z() < c.z_max + 0.5) {
        best_distance = d;
        best = &c;
      }
    }
    return best;
  }

  std::vector<Primitive> cylinders_;
  std::array<std::array<std::array<double, 3>, 4>, 2> sums_{};  ///< [pole, trunk][range bin]: along, |across|, count
};

int run(const OracleOptions& o) {
  SaloamConfig full;
  apply_config_overrides(full, o.set);
  OdometryConfig config = full.odometry;
  if (o.no_semantics) config.use_semantics = false;
  SequenceOptions so;
  so.ignore_labels = !config.use_semantics;
  if (!o.labels.empty()) so.labels_dir = o.labels;
  const SequenceReader reader(o.sequence, so);
  const std::vector<Pose> start = sensor_poses(o.sequence, reader);
  const auto [first_frame, end_frame] = FrameRange::parse(o.frames).clip(reader.size());
  const std::set<int> drop(o.drop.begin(), o.drop.end());
  std::optional<AxisErrors> axes;
  if (!o.trajectory.empty()) axes.emplace(o, reader.velo_to_cam());

  const ClassVoxelSizes voxels = class_voxel_sizes(config);
  const RegistrationSettings settings = RegistrationSettings::from_config(config);
  SemanticLocalMap map = SemanticLocalMap::from_config(config);
  const double period = config.features.sweep_duration, mid = 0.5 * period;
  const Pose origin = mid_sweep(start, first_frame).inverse();
  Vector6d offset_sum = Vector6d::Zero();
  int registered = 0;
  for (std::size_t k = first_frame; k < end_frame && k + 1 < start.size(); ++k) {
    ScanFeatures f = features_of(reader.load_scan(k), config, voxels, drop);
    const Pose pose = origin * mid_sweep(start, k);
    const Vector6d motion = se3_log(mid_sweep(start, k > 0 ? k - 1 : k).inverse() * mid_sweep(start, k > 0 ? k : 1));
    deskew(f.edges, motion, period, mid);
    deskew(f.planars, motion, period, mid);
    if (axes) axes->add(f.edges, mid_sweep(start, k));
    if (!map.empty()) {
      const RegistrationResult r = register_scan(f.edges, f.planars, map, pose, settings);
      if (r.ok) {
        offset_sum += se3_log(pose.inverse() * r.pose);
        ++registered;
      }
    }
    map.add_frame(transformed(f.edges, pose), transformed(f.planars, pose));
  }
  const Vector6d m = offset_sum / std::max(1, registered);
  std::printf("mean offset of %d registrations from the ground truth, sensor frame: forward %+.3f left %+.3f up %+.3f mm, "
              "roll %+.4f pitch %+.4f yaw %+.4f mrad\n",
              registered, 1e3 * m[0], 1e3 * m[1], 1e3 * m[2], 1e3 * m[3], 1e3 * m[4], 1e3 * m[5]);
  if (axes) axes->print();
  return 0;
}

}  // namespace
}  // namespace saloam

int main(int argc, char** argv) {
  saloam::OracleOptions o;
  CLI::App app{"Bias of a simulated sequence's odometry features at the ground-truth poses"};
  app.add_option("sequence", o.sequence, "simulated sequence folder")->required();
  app.add_option("--labels", o.labels, "labels folder instead of SEQ/labels");
  app.add_flag("--no-semantics", o.no_semantics, "label-agnostic features");
  app.add_option("--frames", o.frames, "frame range A:B");
  app.add_option("--drop", o.drop, "leave out these class indices (after grouping)")->delimiter(',');
  app.add_option("--set", o.set, "config override key=value (repeatable)");
  app.add_option("--trajectory", o.trajectory, "KITTI poses the sequence was simulated along: axis errors");
  app.add_option("--seed", o.seed, "world seed of the simulation")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    return saloam::run(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "odometry_oracle: %s\n", e.what());
    return 1;
  }
}
