#include "saloam/odometry/gravity.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tsl/robin_map.h>

#include "saloam/core/lie.hpp"
#include "saloam/core/semantic_classes.hpp"

namespace saloam {

namespace {
constexpr double kDeg = M_PI / 180.0;
/// [m] side of the voxels a scan is cut into for votes.
constexpr double kVoteVoxel = 1.0;
/// At most this many points of a scan are looked at (every k-th).
constexpr std::size_t kMaxVotePoints = 60000;
/// [m] Points farther out along an axis do not vote (no sensor sees so far;
/// their voxel keys would not fit).
constexpr double kFarthestVote = 1e5;
/// A voxel needs this many points to vote.
constexpr int kMinVoxelPoints = 6;
/// Planar voxel: smallest eigenvalue below this share of the middle one,
/// and the middle one above kMinSpread (not one ring's stripe) [m^2].
constexpr double kPlanarRatio = 0.05;
constexpr double kMinSpread = 0.005;
/// Linear voxel (a pole's or trunk's axis): the largest eigenvalue this many
/// times the middle one, and at least kMinLength [m^2].
constexpr double kLinearRatio = 8.0;
constexpr double kMinLength = 0.03;
/// Gates of a vote against the reference up [deg]: with labels, a class's
/// vote within this of what it should be; without, a tighter angle.
constexpr double kLabelGate = 40.0;
constexpr double kGeometryGate = 25.0;
/// [m] without labels a ground vote lies at least this far below the sensor.
constexpr double kBelowSensor = 0.5;
/// scan_up() needs this many planar votes.
constexpr std::size_t kMinPlanarVotes = 20;
/// scan_up() tries at most this many of the planar votes' normals.
constexpr std::size_t kMaxCandidates = 96;
/// Weight of a vote of upright structure (a wall's level normal, a pole's
/// axis) against a ground vote's: walls and poles are built plumb, while
/// roads have grades, cambers and ramps (a start on a 20 deg garage ramp
/// whose ground votes weighed as much as the walls still saw up 6 deg off
/// gravity 150 m later).
constexpr double kUprightWeight = 3.0;
/// A candidate up's score grows by this share of itself times its cosine
/// with the sensor's z (scan_up()); candidates farther than kMaxSearchTilt
/// [deg] from the sensor's z are not tried.
constexpr double kUprightPrior = 0.25;
constexpr double kMaxSearchTilt = 60.0;
/// Refinement rounds of a scan's up (votes re-classified each round).
constexpr int kRefineRounds = 4;
/// The scans contradict a given mount only with this many votes behind them.
constexpr double kMinVotesToContradict = 200;

enum class VoteKind : std::uint8_t { kNone, kGround, kWall, kPole };

VoteKind vote_kind(std::uint16_t label) {
  const std::uint16_t c = static_class(label);
  if (is_ground(c)) return VoteKind::kGround;
  if (c == cls::kBuilding || c == cls::kFence) return VoteKind::kWall;
  if (c == cls::kPole || c == cls::kTrunk || c == cls::kTrafficSign) return VoteKind::kPole;
  return VoteKind::kNone;
}

struct VoxelSums {
  int count = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  std::array<int, 4> kinds{};  ///< points per VoteKind
};

/// One voxel's shape: planar (normal), linear (direction) or neither (it
/// still says that something is there).
struct VoxelShape {
  Eigen::Vector3d centre;
  Eigen::Vector3d normal;     ///< planar: the plane's normal
  Eigen::Vector3d direction;  ///< linear: the line's direction
  bool planar = false;
  bool linear = false;
  VoteKind kind = VoteKind::kNone;  ///< the majority of its labelled points (with labels)
};

std::vector<VoxelShape> voxel_shapes(const LabelledCloud& cloud, bool use_labels) {
  struct KeyHash {
    std::size_t operator()(std::uint64_t k) const { return static_cast<std::size_t>(k * 0x9e3779b97f4a7c15ull >> 7); }
  };
  tsl::robin_map<std::uint64_t, VoxelSums, KeyHash> voxels;
  const std::size_t step = std::max<std::size_t>(1, cloud.size() / kMaxVotePoints);
  const bool labels = use_labels && cloud.label.size() == cloud.size();
  for (std::size_t i = 0; i < cloud.size(); i += step) {
    const Eigen::Vector3d p = cloud.points[i].cast<double>();
    if (!p.allFinite() || p.cwiseAbs().maxCoeff() > kFarthestVote) continue;
    const auto cell = [](double v) {
      return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v / kVoteVoxel)) + (1 << 20)) & 0x1fffff;
    };
    const std::uint64_t key = cell(p.x()) | cell(p.y()) << 21 | cell(p.z()) << 42;
    VoxelSums& v = voxels[key];
    ++v.count;
    v.sum += p;
    v.outer.noalias() += p * p.transpose();
    if (labels) ++v.kinds[static_cast<std::size_t>(vote_kind(cloud.label[i]))];
  }
  std::vector<VoxelShape> shapes;
  for (const auto& [key, v] : voxels) {
    if (v.count < kMinVoxelPoints) continue;
    VoxelShape s;
    s.centre = v.sum / v.count;
    const Eigen::Matrix3d covariance = v.outer / v.count - s.centre * s.centre.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(covariance);
    const Eigen::Vector3d l = eig.eigenvalues();
    s.planar = l(0) < kPlanarRatio * l(1) && l(1) > kMinSpread;
    s.linear = l(2) > kLinearRatio * l(1) && l(2) > kMinLength;
    s.normal = eig.eigenvectors().col(0);
    s.direction = eig.eigenvectors().col(2);
    if (labels) {
      const auto best = std::max_element(v.kinds.begin() + 1, v.kinds.end());
      if (*best * 2 > v.count) s.kind = static_cast<VoteKind>(best - v.kinds.begin());
    }
    shapes.push_back(s);
  }
  // The map's order depends only on the keys inserted: the same for one scan.
  return shapes;
}

UpEvidence classify(const std::vector<VoxelShape>& shapes, bool use_labels, const Eigen::Vector3d& up) {
  UpEvidence e;
  const double cos_label = std::cos(kLabelGate * kDeg), sin_label = std::sin(kLabelGate * kDeg);
  const double cos_geometry = std::cos(kGeometryGate * kDeg), sin_geometry = std::sin(kGeometryGate * kDeg);
  for (const VoxelShape& s : shapes) {
    if (use_labels) {
      if (s.kind == VoteKind::kGround && s.planar && std::abs(s.normal.dot(up)) > cos_label) {
        e.along_up.noalias() += s.normal * s.normal.transpose();
        e.along_up_votes += 1;
      } else if (s.kind == VoteKind::kWall && s.planar && std::abs(s.normal.dot(up)) < sin_label) {
        e.level.noalias() += kUprightWeight * s.normal * s.normal.transpose();
        e.level_votes += kUprightWeight;
      } else if (s.kind == VoteKind::kPole && s.linear && std::abs(s.direction.dot(up)) > cos_label) {
        e.along_up.noalias() += kUprightWeight * s.direction * s.direction.transpose();
        e.along_up_votes += kUprightWeight;
      }
      continue;
    }
    if (!s.planar) continue;
    const double n_up = std::abs(s.normal.dot(up));
    if (n_up > cos_geometry && s.centre.dot(up) < -kBelowSensor) {
      e.along_up.noalias() += s.normal * s.normal.transpose();
      e.along_up_votes += 1;
    } else if (n_up < sin_geometry) {
      e.level.noalias() += kUprightWeight * s.normal * s.normal.transpose();
      e.level_votes += kUprightWeight;
    }
  }
  return e;
}

/// How well a candidate up explains a scan: its ground votes (planar,
/// normal within 10 deg of it, below the sensor; with labels of a ground
/// class) count twice, its level votes (with labels: walls) once, and every
/// voxel that lies more than a metre below the ground's median height
/// counts against it four times: nothing is seen through the ground, while
/// through and beyond a wall (which may pass for ground when a sensor looks
/// sideways along a street) much is.
double candidate_score(const std::vector<VoxelShape>& shapes, bool use_labels, const Eigen::Vector3d& up) {
  const double cos_tight = std::cos(10.0 * kDeg), sin_tight = std::sin(10.0 * kDeg);
  std::vector<double> ground_heights;
  double level = 0;
  for (const VoxelShape& s : shapes) {
    if (!s.planar) continue;
    const double n_up = std::abs(s.normal.dot(up));
    const double height = s.centre.dot(up);
    const bool ground_class = !use_labels || s.kind == VoteKind::kGround;
    const bool wall_class = !use_labels || s.kind == VoteKind::kWall;
    if (ground_class && n_up > cos_tight && height < -kBelowSensor) ground_heights.push_back(height);
    else if (wall_class && n_up < sin_tight) level += 1;
  }
  if (ground_heights.empty()) return level;
  const auto middle = ground_heights.begin() + static_cast<std::ptrdiff_t>(ground_heights.size() / 2);
  std::nth_element(ground_heights.begin(), middle, ground_heights.end());
  const double ground = *middle;
  double below = 0;
  for (const VoxelShape& s : shapes) below += s.centre.dot(up) < ground - 1.0 ? 1 : 0;
  return 2.0 * static_cast<double>(ground_heights.size()) + level - 4.0 * below;
}

Eigen::Vector3d refined_up(const std::vector<VoxelShape>& shapes, bool use_labels, Eigen::Vector3d up) {
  for (int round = 0; round < kRefineRounds; ++round) {
    const auto better = solve_up(classify(shapes, use_labels, up), up);
    if (!better) break;
    up = *better;
  }
  return up;
}
}  // namespace

UpEvidence& UpEvidence::operator+=(const UpEvidence& other) {
  along_up += other.along_up;
  level += other.level;
  along_up_votes += other.along_up_votes;
  level_votes += other.level_votes;
  return *this;
}

UpEvidence UpEvidence::rotated(const Eigen::Matrix3d& R) const {
  UpEvidence out = *this;
  out.along_up = R * along_up * R.transpose();
  out.level = R * level * R.transpose();
  return out;
}

std::optional<Eigen::Vector3d> solve_up(const UpEvidence& e, const Eigen::Vector3d& reference) {
  // One up vote fixes the axis; level votes alone leave it free about their
  // common direction unless they span two directions.
  if (e.along_up_votes < 1 && e.level_votes < 2) return std::nullopt;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(e.level - e.along_up);
  Eigen::Vector3d u = eig.eigenvectors().col(0).normalized();
  if (!u.allFinite()) return std::nullopt;
  // The smallest eigenvalue must stand alone, or the direction is a guess.
  const Eigen::Vector3d l = eig.eigenvalues();
  if (l(1) - l(0) < 1e-6 * std::max(1.0, e.votes())) return std::nullopt;
  if (u.dot(reference) < 0) u = -u;
  return u;
}

double up_spread_deg(const UpEvidence& e, const Eigen::Vector3d& up) {
  if (e.votes() <= 0) return 0.0;
  // sum (d . u)^2 over up votes is sum cos^2 = votes - sum sin^2; over level
  // votes sum (n . u)^2 is sum sin^2 of their angle from level.
  const double up_sin2 = e.along_up_votes - up.dot(e.along_up * up);
  const double level_sin2 = up.dot(e.level * up);
  const double mean_sin2 = std::max(0.0, (up_sin2 + level_sin2) / e.votes());
  return std::asin(std::min(1.0, std::sqrt(mean_sin2))) / kDeg;
}

UpEvidence scan_up_evidence(const LabelledCloud& cloud, bool use_labels, const Eigen::Vector3d& reference) {
  return classify(voxel_shapes(cloud, use_labels), use_labels, reference.normalized());
}

std::optional<Eigen::Vector3d> scan_up(const LabelledCloud& cloud, bool use_labels,
                                       const std::optional<Eigen::Vector3d>& prior) {
  const std::vector<VoxelShape> shapes = voxel_shapes(cloud, use_labels);
  std::vector<const VoxelShape*> planar;
  for (const VoxelShape& s : shapes) {
    if (s.planar) planar.push_back(&s);
  }
  if (planar.size() < kMinPlanarVotes) return std::nullopt;
  if (prior) return refined_up(shapes, use_labels, prior->normalized());
  // Candidates: the sensor's z and every k-th planar normal, both signs.
  std::vector<Eigen::Vector3d> candidates{Eigen::Vector3d::UnitZ()};
  const std::size_t step = std::max<std::size_t>(1, planar.size() / kMaxCandidates);
  for (std::size_t i = 0; i < planar.size(); i += step) {
    candidates.push_back(planar[i]->normal);
    candidates.push_back(-planar[i]->normal);
  }
  Eigen::Vector3d best = candidates.front();
  double best_score = -1;
  for (const Eigen::Vector3d& c : candidates) {
    // Sensors are mounted about upright more often than not: in a box of a
    // room or a corridor, where a wall explains the scan as well as the
    // floor, the candidate nearer the sensor's z wins, and none beyond
    // kMaxSearchTilt is taken (a sensor mounted on its side needs its mount
    // or an IMU).
    if (c.z() < std::cos(kMaxSearchTilt * kDeg)) continue;
    const double score = candidate_score(shapes, use_labels, c) * (1.0 + kUprightPrior * std::max(0.0, c.z()));
    if (score > best_score) {
      best_score = score;
      best = c;
    }
  }
  return refined_up(shapes, use_labels, best);
}

Eigen::Matrix3d level_rotation(const Eigen::Vector3d& up) {
  return Eigen::Quaterniond::FromTwoVectors(up.normalized(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

bool points_up(const Eigen::Vector3d& up) { return up.normalized().z() >= 1.0 - 1e-7; }

LabelledCloud turned(const LabelledCloud& scan, const Eigen::Matrix3d& rotation) {
  LabelledCloud out = scan;
  const Eigen::Matrix3f R = rotation.cast<float>();
  for (Eigen::Vector3f& p : out.points) p = R * p;
  return out;
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kDeg;
}

Eigen::Vector3d mount_up(const std::vector<double>& rpy) {
  if (rpy.size() != 3) return Eigen::Vector3d::UnitZ();
  return rotation_from_rpy_deg(Eigen::Vector3d(rpy[0], rpy[1], rpy[2])).transpose() * Eigen::Vector3d::UnitZ();
}

const char* up_source_name(UpSource source) {
  switch (source) {
    case UpSource::kMount: return "the mount (odometry.gravity.mount_rpy_deg)";
    case UpSource::kImu: return "the sensor's IMU at rest";
    case UpSource::kScans: return "the scans";
    case UpSource::kSensorAxis: return "the sensor's z (assumed)";
  }
  return "?";
}

const char* up_source_key(UpSource source) {
  switch (source) {
    case UpSource::kMount: return "mount";
    case UpSource::kImu: return "imu";
    case UpSource::kScans: return "scans";
    case UpSource::kSensorAxis: return "sensor_z";
  }
  return "?";
}

std::string GravityReport::describe() const {
  std::string text = fmt::format("up ({:.3f}, {:.3f}, {:.3f}) in the first scan's frame, from {}, {:.1f} deg from the "
                                 "sensor's z",
                                 up.x(), up.y(), up.z(), up_source_name(source), tilt_deg());
  if (votes > 0) text += fmt::format(" ({:.0f} votes of the scans, spread {:.1f} deg)", votes, spread_deg);
  if (scans_up) text += fmt::format("; the scans' own up is {:.1f} deg from it", angle_deg(*scans_up, up));
  return text;
}

void GravityTracker::start(const LabelledCloud& first_scan, bool use_labels) {
  started_ = true;
  const bool mount = config_.mount_rpy_deg.size() == 3;
  const bool imu = config_.use_imu && config_.imu_up.has_value();
  const bool given = mount || imu;
  if (mount) {
    source_ = UpSource::kMount;
    up_ = mount_up(config_.mount_rpy_deg);
  } else if (imu) {
    source_ = UpSource::kImu;
    up_ = config_.imu_up->normalized();
  } else if (!config_.estimate) {
    source_ = UpSource::kSensorAxis;
    up_ = Eigen::Vector3d::UnitZ();
    return;
  }
  // A given up is refined by the scans (to check it), not searched for.
  const std::optional<Eigen::Vector3d> from_scan =
      scan_up(first_scan, use_labels, given ? std::optional<Eigen::Vector3d>(up_) : std::nullopt);
  if (!from_scan) return;
  evidence_ = scan_up_evidence(first_scan, use_labels, *from_scan);
  scans_up_ = *from_scan;
  scans_up_known_ = true;
  if (!given) {
    source_ = UpSource::kScans;
    up_ = *from_scan;
  }
  check_mount();
}

void GravityTracker::check_mount() {
  if (source_ != UpSource::kMount || !scans_up_known_ || warned_ || evidence_.votes() < kMinVotesToContradict) return;
  // (An IMU's up is measured, not stated: the scans' is reported beside it, not warned about.)
  const double off = angle_deg(scans_up_, up_);
  if (off <= config_.mount_warning_deg) return;
  warned_ = true;
  spdlog::warn("the mount's up ({:.3f}, {:.3f}, {:.3f}) and the scans' up ({:.3f}, {:.3f}, {:.3f}) differ by {:.1f} deg "
               "(odometry.gravity.mount_warning_deg {}): the mount's is used; check odometry.gravity.mount_rpy_deg "
               "(R_base<-sensor as roll, pitch, yaw)",
               up_.x(), up_.y(), up_.z(), scans_up_.x(), scans_up_.y(), scans_up_.z(), off, config_.mount_warning_deg);
}

void GravityTracker::observe(const LabelledCloud& scan, bool use_labels, const Eigen::Matrix3d& world_from_sensor,
                             std::size_t frame) {
  if (!started_ || (source_ == UpSource::kSensorAxis && !scans_up_known_ && !config_.estimate)) return;
  if (frame % static_cast<std::size_t>(std::max(1, config_.refine_every_frames)) != 0) return;
  const Eigen::Vector3d reference = scans_up_known_ ? scans_up_ : up_;
  evidence_ += scan_up_evidence(scan, use_labels, world_from_sensor.transpose() * reference).rotated(world_from_sensor);
  const std::optional<Eigen::Vector3d> refined = solve_up(evidence_, reference);
  if (!refined) return;
  scans_up_ = *refined;
  scans_up_known_ = true;
  if (source_ == UpSource::kScans || source_ == UpSource::kSensorAxis) {
    source_ = UpSource::kScans;
    up_ = scans_up_;
  }
  check_mount();
}

GravityReport GravityTracker::report() const {
  GravityReport r;
  r.up = up_;
  r.source = source_;
  r.votes = evidence_.votes();
  if (r.votes > 0) r.spread_deg = up_spread_deg(evidence_, scans_up_known_ ? scans_up_ : up_);
  if ((source_ == UpSource::kMount || source_ == UpSource::kImu) && scans_up_known_) r.scans_up = scans_up_;
  return r;
}

}  // namespace saloam
