// `saloam odom`: semantic-assisted LOAM odometry over a sequence folder.
// Writes poses.txt (KITTI camera-frame convention, comparable with the
// ground truth), poses_tum.txt (LiDAR frame) and timing.json. Poses are
// flushed frame by frame so an interrupted run keeps what it computed.

#include <algorithm>
#include <fstream>
#include <iostream>
#include <memory>
#include <numeric>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/odometry/pipeline.hpp"

namespace saloam::cli {
namespace {

struct OdomOptions {
  std::string sequence;
  std::string out;
  std::string labels;
  std::string frames;
  bool no_semantics = false;
  ConfigOptions config;
};

/// "A:B" -> [A, B) clipped to n; "A:" or "A" -> [A, n).
std::pair<std::size_t, std::size_t> parse_frames(const std::string& text, std::size_t n) {
  if (text.empty()) return {0, n};
  const auto colon = text.find(':');
  try {
    const std::size_t a = std::stoul(text.substr(0, colon));
    std::size_t b = n;
    if (colon != std::string::npos && colon + 1 < text.size()) b = std::stoul(text.substr(colon + 1));
    b = std::min(b, n);
    if (a >= b) throw ConfigError(fmt::format("--frames {}: empty range (sequence has {} frames)", text, n));
    return {a, b};
  } catch (const std::logic_error&) {
    throw ConfigError(fmt::format("--frames {}: expected A:B with frame indices", text));
  }
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

nlohmann::json stage_stats(const std::vector<double>& ms) {
  const double mean = ms.empty() ? 0.0 : std::accumulate(ms.begin(), ms.end(), 0.0) / ms.size();
  return {{"mean_ms", mean},
          {"median_ms", median(ms)},
          {"max_ms", ms.empty() ? 0.0 : *std::max_element(ms.begin(), ms.end())}};
}

void write_timing_json(const std::filesystem::path& file, const OdometryPipeline& odometry) {
  std::vector<double> features, deskew, registration, map, total;
  for (const auto& t : odometry.timings()) {
    features.push_back(t.features_ms);
    deskew.push_back(t.deskew_downsample_ms);
    registration.push_back(t.registration_ms);
    map.push_back(t.map_update_ms);
    total.push_back(t.total_ms());
  }
  const double med = median(total);
  const double worst = total.empty() ? 0.0 : *std::max_element(total.begin(), total.end());
  nlohmann::json j{{"frames", total.size()},
                   {"hz_median", med > 0 ? 1000.0 / med : 0.0},
                   {"hz_worst_frame", worst > 0 ? 1000.0 / worst : 0.0},
                   {"stages",
                    {{"features", stage_stats(features)},
                     {"deskew_downsample", stage_stats(deskew)},
                     {"registration", stage_stats(registration)},
                     {"map_update", stage_stats(map)},
                     {"total", stage_stats(total)}}},
                   {"frame_total_ms", total}};
  std::ofstream out(file);
  if (!out) throw InputError(file, "cannot write timing file");
  out << j.dump(2) << "\n";
}

int run_odom(const OdomOptions& options) {
  SaloamConfig config = options.config.resolve();
  if (options.no_semantics) config.odometry.use_semantics = false;
  SequenceOptions seq_options;
  if (!options.labels.empty()) seq_options.labels_dir = options.labels;
  seq_options.ignore_labels = !config.odometry.use_semantics;
  const SequenceReader reader(options.sequence, seq_options);
  const auto [first, last] = parse_frames(options.frames, reader.size());
  if (config.odometry.use_semantics && !reader.has_labels()) {
    spdlog::warn("{}: no labels found; running with every point in one class", options.sequence);
  }

  const std::filesystem::path out_dir(options.out);
  std::filesystem::create_directories(out_dir);
  std::optional<Pose> tr;
  if (reader.has_calib()) {
    tr = reader.velo_to_cam();
  } else {
    spdlog::warn("{}: no calib.txt; poses.txt holds LiDAR-frame poses, not the KITTI camera convention",
                 options.sequence);
  }
  std::ofstream kitti_out(out_dir / "poses.txt");
  std::ofstream tum_out(out_dir / "poses_tum.txt");
  if (!kitti_out || !tum_out) throw InputError(out_dir, "cannot write pose files");

  OdometryPipeline odometry(config.odometry);
  ProgressBar progress(last - first, "odom");
  std::size_t failures = 0;
  for (std::size_t i = first; i < last && !stop_requested(); ++i) {
    const LabelledCloud cloud = reader.load_scan(i);
    const double t = reader.times().at(i);
    const Pose q = odometry.register_frame(cloud, t);
    if (odometry.poses().size() > 1 && !odometry.last_frame_stats().registration.ok) {
      ++failures;
      spdlog::warn("frame {}: registration failed (too few correspondences); kept the prediction", i);
    }
    const Pose p = tr ? orthonormalized(*tr * q * tr->inverse()) : q;
    kitti_out << kitti_pose_line(p) << '\n' << std::flush;
    tum_out << tum_pose_line(t, q) << '\n' << std::flush;
    const auto& timing = odometry.timings().back();
    progress.set_status(fmt::format("{:.0f} ms", timing.total_ms()));
    progress.advance();
  }
  progress.finish();
  write_timing_json(out_dir / "timing.json", odometry);
  std::vector<double> total;
  for (const auto& t : odometry.timings()) total.push_back(t.total_ms());
  const double med = median(total);
  std::cout << fmt::format("{} frames, {} registration failures, median {:.1f} ms/frame ({:.1f} Hz)\n",
                           odometry.poses().size(), failures, med, med > 0 ? 1000.0 / med : 0.0);
  std::cout << fmt::format("wrote {}, {}, {}\n", (out_dir / "poses.txt").string(),
                           (out_dir / "poses_tum.txt").string(), (out_dir / "timing.json").string());
  if (stop_requested()) {
    spdlog::warn("interrupted: {} frames written", odometry.poses().size());
    return 130;
  }
  return 0;
}

const CommandRegistration kRegistration{Command{
    "odom", "Semantic-assisted LOAM odometry over a sequence folder", 30, [](CLI::App& app) {
      auto options = std::make_shared<OdomOptions>();
      app.add_option("SEQ_DIR", options->sequence, "Sequence folder (velodyne/, labels/, calib.txt, times.txt)")
          ->required();
      app.add_option("--out", options->out, "Output folder for poses.txt, poses_tum.txt, timing.json")->required();
      app.add_option("--labels", options->labels, "Folder of .label files to use instead of SEQ_DIR/labels");
      app.add_flag("--no-semantics", options->no_semantics,
                   "Label-agnostic run with plain voxel grid (FLOAM-like baseline)");
      app.add_option("--frames", options->frames, "Frame range A:B (B exclusive; A: = to the end)");
      options->config.add_to(app);
      return [options] { return run_odom(*options); };
    }}};

}  // namespace
}  // namespace saloam::cli
