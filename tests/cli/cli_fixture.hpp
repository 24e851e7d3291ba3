#pragma once
// What the end-to-end tests of the output and input checks share: the
// program, tiny sequences written by the test itself, file contents.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/sequence.hpp"
#include "testing/test_support.hpp"

namespace saloam::testing {

inline std::string saloam_cmd(const std::string& args) { return quoted(cli_path()) + " " + args; }

/// A labelled scan: a few poles and a building wall around the sensor.
inline LabelledCloud street_scan() {
  LabelledCloud cloud;
  cloud.has_labels = true;
  for (int k = 0; k < 6; ++k) {
    const float x = -15.0F + 6.0F * static_cast<float>(k);
    for (int i = 0; i < 60; ++i) cloud.push_back({x, 5.0F, -1.5F + 0.05F * static_cast<float>(i)}, 0.3F, cls::kPole, 0);
    for (int i = 0; i < 200; ++i)
      cloud.push_back({x + 0.02F * static_cast<float>(i), -8.0F, -1.5F + 0.02F * static_cast<float>(i % 50)}, 0.3F,
                      cls::kBuilding, 0);
  }
  return cloud;
}

/// `seq` with `frames` street scans, poses.txt (moving 0.1 m a frame along z), times.txt and calib.txt.
inline std::filesystem::path write_street_sequence(const std::filesystem::path& seq, std::size_t frames = 4) {
  SequenceWriter writer(seq);
  std::vector<Pose> poses;
  std::vector<double> times;
  for (std::size_t i = 0; i < frames; ++i) {
    writer.write_scan(i, street_scan());
    Pose pose = Pose::Identity();
    pose.translation() = Eigen::Vector3d(0, 0, 0.1 * static_cast<double>(i));
    poses.push_back(pose);
    times.push_back(0.1 * static_cast<double>(i));
  }
  writer.write_camera_poses(poses);
  writer.write_times(times);
  writer.write_calib(Pose::Identity());
  return seq;
}

inline std::string file_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

inline std::size_t line_count(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::size_t lines = 0;
  for (std::string line; std::getline(in, line);) lines += !line.empty() && line[0] != '#';
  return lines;
}

/// Runs `saloam ARGS`; expects exit status 2 (an input error) and returns the output.
inline std::string failure_of(const std::string& args) {
  std::string output;
  EXPECT_EQ(run_command(saloam_cmd(args), &output), 2) << args << "\n" << output;
  return output;
}

inline void expect_has(const std::string& output, const std::string& fragment) {
  EXPECT_NE(output.find(fragment), std::string::npos) << "missing '" << fragment << "' in:\n" << output;
}

/// Runs `saloam ARGS` (a command that needs libtorch, in a build without it):
/// expects a failure that says so.
inline void expect_needs_libtorch(const std::string& args) {
  std::string output;
  EXPECT_NE(run_command(saloam_cmd(args), &output), 0) << args;
  expect_has(output, "built without libtorch");
}

}  // namespace saloam::testing
