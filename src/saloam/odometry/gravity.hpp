#pragma once
// Which way is up (odometry.gravity, GravityConfig): the direction opposite
// to gravity, as a unit vector in the world frame (the first scan's sensor
// frame, which the outputs keep whatever the sensor's tilt). The odometry's
// rules that mean "horizontal" or "vertical" (the plane constraint, level
// lines, the ground below which no edges are taken, a thin object's axis),
// the place descriptors and the loop guesses take it from here instead of
// assuming that the sensor's z is up.
//
// Up comes, in order of trust, from the mount given in the configuration
// (R_base<-sensor: up = R^T z), or from the scans, or is the sensor's z.
// From the scans, surfaces say which way is up: the ground's normal and the
// axes of poles and trunks point up, upright walls' normals lie level. Each
// looked-at scan is cut into 1 m voxels; a voxel whose points lie on a plane
// (or a line) gives its normal (or direction) as one vote. With labels the
// votes' classes say which is which (ground classes, building and fence,
// pole/trunk/traffic-sign); without, their angle to the current estimate
// does. Upright structure's votes weigh 3, the ground's 1 (walls and poles
// are built plumb; roads have grades, cambers and ramps). Up is the unit u
// minimising
//     sum_level w (n . u)^2 - sum_up w (d . u)^2,
// the eigenvector of the smallest eigenvalue of sum_level n n^T - sum_up d d^T:
// one linear solve, no angle wrap. The first scan's up is searched among
// every planar vote's normal (so a sensor tilted by any angle, even
// sideways, is found), then refined; votes of later scans are rotated into
// the world by the odometry's poses and added, so a start on a ramp (whose
// ground's normal is not up) is corrected as the run reaches level road and
// upright walls.

#include <optional>
#include <string>

#include <Eigen/Core>

#include "saloam/core/config.hpp"
#include "saloam/core/types.hpp"

namespace saloam {

/// Votes for the up direction, in one frame: weighted sums of outer
/// products (a vote of upright structure, a wall or a pole, weighs 3, one
/// of the ground 1: walls and poles are built plumb, roads have grades and
/// ramps).
struct UpEvidence {
  Eigen::Matrix3d along_up = Eigen::Matrix3d::Zero();  ///< sum w d d^T of directions that point up (ground normals, pole axes)
  Eigen::Matrix3d level = Eigen::Matrix3d::Zero();     ///< sum w n n^T of normals that lie level (upright walls)
  double along_up_votes = 0;  ///< sum of their weights
  double level_votes = 0;     ///< sum of their weights

  UpEvidence& operator+=(const UpEvidence& other);
  /// The same votes seen from another frame: R * evidence * R^T for R = R_to<-from.
  [[nodiscard]] UpEvidence rotated(const Eigen::Matrix3d& R_to_from) const;
  [[nodiscard]] double votes() const { return along_up_votes + level_votes; }
};

/// The up direction these votes give, on the side of `reference` (u . reference
/// >= 0), or nothing without both an up vote and a level pair to fix it.
std::optional<Eigen::Vector3d> solve_up(const UpEvidence& evidence, const Eigen::Vector3d& reference);

/// How well the votes agree with `up`: the RMS angle [deg] of the up votes
/// from up and of the level votes from level, pooled.
double up_spread_deg(const UpEvidence& evidence, const Eigen::Vector3d& up);

/// The votes of one scan (sensor frame), each classified against
/// `reference` (the current estimate of up in the sensor frame): with
/// labels by class and within 40 deg of what the class should be, without
/// labels by angle alone (ground: normal within 25 deg of up and the voxel
/// below the sensor; level: within 25 deg of level).
UpEvidence scan_up_evidence(const LabelledCloud& cloud, bool use_labels, const Eigen::Vector3d& reference);

/// Up in the frame of a single scan. With no prior, each planar vote's
/// normal (both signs) within 60 deg of the sensor's z is tried as up and
/// scored by the votes it explains (the sensor's z slightly preferred: in a
/// room a wall explains a scan as well as the floor; a sensor mounted on its
/// side needs its mount or an IMU); the best is refined with the votes
/// classified against it. With a prior (a mount, an IMU), the prior is
/// refined. Nothing when the scan has too few planar votes (fewer than 20).
std::optional<Eigen::Vector3d> scan_up(const LabelledCloud& cloud, bool use_labels,
                                       const std::optional<Eigen::Vector3d>& prior = std::nullopt);

/// The rotation of least angle taking `up` to z: R * up = (0, 0, 1), the
/// frame of a scan turned level (yaw unchanged as far as a tilt allows).
Eigen::Matrix3d level_rotation(const Eigen::Vector3d& up);

/// Whether `up` is the frame's z within about 0.03 deg: the frame is level
/// as it is (nothing to turn).
bool points_up(const Eigen::Vector3d& up);

/// The scan with its points turned by `rotation` (every other field kept).
LabelledCloud turned(const LabelledCloud& scan, const Eigen::Matrix3d& rotation);

/// Angle between two directions [deg].
double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

/// Up in the sensor frame from a mount R_base<-sensor given as roll, pitch, yaw [deg].
Eigen::Vector3d mount_up(const std::vector<double>& mount_rpy_deg);

/// Where a run's up came from.
enum class UpSource { kMount, kImu, kScans, kSensorAxis };
const char* up_source_name(UpSource source);
/// One word for files: "mount", "imu", "scans", "sensor_z".
const char* up_source_key(UpSource source);

/// What the summary says about up.
struct GravityReport {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< in the world (first scan's sensor) frame
  UpSource source = UpSource::kSensorAxis;
  double votes = 0;          ///< scan votes behind the scans' estimate
  double spread_deg = 0;     ///< up_spread_deg of those votes about the estimate
  /// The scans' own estimate when up is the mount's or the IMU's (to check it).
  std::optional<Eigen::Vector3d> scans_up;
  /// [deg] angle between up and the sensor's z at the first scan.
  [[nodiscard]] double tilt_deg() const { return angle_deg(up, Eigen::Vector3d::UnitZ()); }
  /// One line: "up (x, y, z): from the scans, tilted 20.1 deg from the sensor's z (3,210 votes, spread 2.3 deg)".
  [[nodiscard]] std::string describe() const;
};

/// Up for one run, as the odometry needs it: set from the mount or the first
/// scan, then (from the scans) refined every refine_every_frames frames with
/// the scan's votes rotated into the world by its registered pose.
class GravityTracker {
 public:
  explicit GravityTracker(GravityConfig config) : config_(std::move(config)) {}

  /// Sets up from the mount or from the first scan (sensor frame = world).
  void start(const LabelledCloud& first_scan, bool use_labels);
  /// Adds the votes of a registered scan (R_world<-sensor its rotation) when one is due.
  void observe(const LabelledCloud& scan, bool use_labels, const Eigen::Matrix3d& world_from_sensor, std::size_t frame);
  [[nodiscard]] bool started() const { return started_; }
  /// Up in the world frame (the sensor's z until started).
  [[nodiscard]] const Eigen::Vector3d& up() const { return up_; }
  [[nodiscard]] GravityReport report() const;

 private:
  /// Warns once when the scans' up contradicts a given mount (mount_warning_deg).
  void check_mount();

  GravityConfig config_;
  bool started_ = false;
  UpSource source_ = UpSource::kSensorAxis;
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d scans_up_ = Eigen::Vector3d::UnitZ();  ///< the scans' estimate (= up_ from the scans)
  bool scans_up_known_ = false;
  bool warned_ = false;
  UpEvidence evidence_;  ///< world frame
};

}  // namespace saloam
