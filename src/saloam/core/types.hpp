#pragma once
// Basic data types shared by every module: labelled point clouds, poses, trajectories.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace saloam {

/// A rigid transform T_a<-b in SE(3). Compose with `*`; keep it on the
/// manifold with `orthonormalized()` (see lie.hpp) after every update.
using Pose = Eigen::Isometry3d;

/// One LiDAR scan with per-point semantics, stored as parallel arrays
/// (structure of arrays: the hot loops touch one field at a time).
///
/// `label` is the raw SemanticKITTI class id (low 16 bits of a .label entry),
/// `instance` the instance id (high 16 bits). A cloud without label data has
/// every label 0 ("unlabeled") and `has_labels == false`.
///
/// Optional per-point fields, present only when the source records them
/// (PCD, PLY, PointCloud2 with such fields; the KITTI .bin format has none):
/// `ring` is the laser (beam) index, `time` the instant the point was
/// measured, in seconds relative to the scan's timestamp (negative before
/// it). Each is either empty or holds one entry per point: push_back without
/// the field drops it from the whole cloud, push_back_from carries it while
/// every point has it.
struct LabelledCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> remission;
  std::vector<std::uint16_t> label;
  std::vector<std::uint16_t> instance;
  std::vector<std::uint16_t> ring;  ///< empty, or the beam index of every point
  std::vector<float> time;          ///< empty, or every point's time [s] relative to the scan's timestamp
  bool has_labels = false;

  [[nodiscard]] std::size_t size() const { return points.size(); }
  [[nodiscard]] bool empty() const { return points.empty(); }
  [[nodiscard]] bool has_rings() const { return !ring.empty() && ring.size() == points.size(); }
  [[nodiscard]] bool has_times() const { return !time.empty() && time.size() == points.size(); }

  void reserve(std::size_t n) {
    points.reserve(n);
    remission.reserve(n);
    label.reserve(n);
    instance.reserve(n);
  }
  void clear() {
    points.clear();
    remission.clear();
    label.clear();
    instance.clear();
    ring.clear();
    time.clear();
  }
  /// Appends a point without ring or time: the cloud then has neither.
  void push_back(const Eigen::Vector3f& p, float r, std::uint16_t cls = 0, std::uint16_t inst = 0) {
    points.push_back(p);
    remission.push_back(r);
    label.push_back(cls);
    instance.push_back(inst);
    ring.clear();
    time.clear();
  }
  /// Copies point i of `other` (all fields) to the end of this cloud. Ring
  /// and time come along when `other` has them and every point here has them
  /// too (or this cloud was empty); otherwise this cloud has none.
  void push_back_from(const LabelledCloud& other, std::size_t i) {
    const std::size_t n = size();
    points.push_back(other.points[i]);
    remission.push_back(other.remission[i]);
    label.push_back(other.label[i]);
    instance.push_back(other.instance[i]);
    append_optional(ring, n, other.has_rings() ? &other.ring[i] : nullptr);
    append_optional(time, n, other.has_times() ? &other.time[i] : nullptr);
  }

 private:
  /// Appends *value to `field` when it held one value for each of the `n`
  /// points before; otherwise (or without a value) the cloud loses the field.
  template <class T>
  static void append_optional(std::vector<T>& field, std::size_t n, const T* value) {
    if (value && field.size() == n) {
      field.push_back(*value);
    } else {
      field.clear();
    }
  }
};

/// A sequence of poses with their timestamps (seconds). `poses[i]` maps
/// points of frame i into the trajectory's world frame.
struct Trajectory {
  std::vector<double> timestamps;
  std::vector<Pose> poses;

  [[nodiscard]] std::size_t size() const { return poses.size(); }
  [[nodiscard]] bool empty() const { return poses.empty(); }
};

}  // namespace saloam
