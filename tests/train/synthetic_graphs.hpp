#pragma once
// Synthetic graph sequences for the trainer's tests: a straight street of
// random landmarks (class, position); a sensor drives along it and back
// (a reverse-direction revisit), and the graph of a frame is the landmarks
// within 30 m in the sensor frame. Nearby frames share most landmarks.

#include <cmath>
#include <random>

#include "saloam/train/graph_dataset.hpp"

namespace saloam::testing {

inline GraphSequence synthetic_street(std::uint64_t seed, double length = 200.0, double spacing = 2.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> along(-30.0, length + 30.0), across(-15.0, 15.0), height(-1.5, 3.0);
  std::uniform_int_distribution<int> label(0, kNumNodeClasses - 1);
  std::vector<std::pair<int, Eigen::Vector3d>> landmarks;
  for (int i = 0; i < static_cast<int>(length / 2.5); ++i)
    landmarks.emplace_back(label(rng), Eigen::Vector3d(along(rng), across(rng), height(rng)));
  GraphSequence sequence;
  sequence.name = "street-" + std::to_string(seed);
  auto add_frame = [&](double x, double heading) {
    const Eigen::Vector3d position(x, 0.0, 0.0);
    const Eigen::Matrix3d to_sensor = Eigen::AngleAxisd(-heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    SemanticGraph graph;
    for (const auto& [c, p] : landmarks) {
      if ((p - position).head<2>().norm() > 30.0) continue;
      graph.nodes.push_back(c);
      graph.centers.push_back(to_sensor * (p - position));
    }
    sequence.graphs.push_back(graph);
    sequence.positions.push_back(position);
  };
  for (double x = 0; x <= length; x += spacing) add_frame(x, 0.0);
  for (double x = length - spacing / 2; x >= 0; x -= spacing) add_frame(x, M_PI);  // back, facing the other way
  return sequence;
}

}  // namespace saloam::testing
