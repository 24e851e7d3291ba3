#include "saloam/sim/render.hpp"

#include <algorithm>
#include <cmath>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/lie.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/viz/canvas.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

MapRenderStats render_map(const SequenceReader& reader, const fs::path& png, const MapRenderOptions& options) {
  const std::vector<Pose> poses = reader.lidar_poses();
  const std::size_t n = reader.size();
  const std::size_t step = options.frame_step > 0 ? options.frame_step : std::max<std::size_t>(1, n / 300);

  // Extent: trajectory plus the range kept around it.
  Eigen::Vector2d lo = poses.front().translation().head<2>(), hi = lo;
  for (std::size_t i = 0; i < n; ++i) {
    lo = lo.cwiseMin(poses[i].translation().head<2>());
    hi = hi.cwiseMax(poses[i].translation().head<2>());
  }
  const double margin = std::min(options.max_range, 50.0);
  lo.array() -= margin;
  hi.array() += margin;
  TopDownCanvas canvas(lo, hi, options.picture);
  std::size_t scans_used = 0;
  ProgressBar progress((n + step - 1) / step, "render map", options.show_progress);
  for (std::size_t i = 0; i < n; i += step) {
    if (stop_requested()) break;
    const LabelledCloud cloud = reader.load_scan(i);
    const Pose& T = poses[i];
    // De-skew: a point at azimuth a was measured at fraction (pi - a) / 2 pi
    // of the 0.1 s sweep (clockwise from behind), on the way to the next pose.
    Pose motion = Pose::Identity();
    double sweep_share = 0.0;
    if (options.deskew && n > 1) {
      const std::size_t j = i + 1 < n ? i + 1 : i - 1;
      const double dt = std::abs(reader.times()[j] - reader.times()[i]);
      motion = i + 1 < n ? Pose(T.inverse() * poses[j]) : Pose(poses[j].inverse() * T);
      sweep_share = dt > 1e-6 ? std::min(1.0, 0.1 / dt) : 0.0;
    }
    for (std::size_t k = 0; k < cloud.size(); ++k) {
      const Eigen::Vector3f& q = cloud.points[k];
      if (q.head<2>().norm() > options.max_range) continue;
      Eigen::Vector3d w;
      if (sweep_share > 0) {
        const double s = (kPi - std::atan2(q.y(), q.x())) / (2 * kPi) * sweep_share;
        w = T * (interpolate(Pose::Identity(), motion, s) * q.cast<double>());
      } else {
        w = T * q.cast<double>();
      }
      canvas.add(w, cloud.has_labels ? cloud.label[k] : 0, cloud.has_labels);
    }
    ++scans_used;
    progress.advance();
  }
  progress.finish();

  MapRenderStats stats;
  static_cast<TopDownStats&>(stats) = canvas.save(png, poses);
  stats.scans_used = scans_used;
  return stats;
}

}  // namespace saloam
