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
struct LabelledCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> remission;
  std::vector<std::uint16_t> label;
  std::vector<std::uint16_t> instance;
  bool has_labels = false;

  [[nodiscard]] std::size_t size() const { return points.size(); }
  [[nodiscard]] bool empty() const { return points.empty(); }

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
  }
  void push_back(const Eigen::Vector3f& p, float r, std::uint16_t cls = 0, std::uint16_t inst = 0) {
    points.push_back(p);
    remission.push_back(r);
    label.push_back(cls);
    instance.push_back(inst);
  }
  /// Copies point i of `other` (all fields) to the end of this cloud.
  void push_back_from(const LabelledCloud& other, std::size_t i) {
    push_back(other.points[i], other.remission[i], other.label[i], other.instance[i]);
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
