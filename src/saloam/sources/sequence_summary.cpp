#include "saloam/sources/sequence_summary.hpp"

#include <algorithm>

namespace saloam {

SequenceSummary summarize(FrameSource& source, std::size_t scans_to_read) {
  const SourceInfo& info = source.info();
  SequenceSummary s;
  s.format = info.format;
  s.frames = source.size();
  const auto& t = info.times;
  if (!t.empty()) {
    s.first_time = t.front();
    s.last_time = t.back();
  }
  if (t.size() > 1) {
    std::vector<double> dt(t.size() - 1);
    for (std::size_t i = 1; i < t.size(); ++i) dt[i - 1] = t[i] - t[i - 1];
    std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
    s.median_interval = dt[dt.size() / 2];
  }
  const std::size_t n = std::min(scans_to_read, source.size());
  double points = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = n == 1 ? 0 : k * (source.size() - 1) / (n - 1);
    const LabelledCloud cloud = source.scan(i);
    points += static_cast<double>(cloud.size());
    if (k == 0) {
      s.lasers = find_lasers(cloud);
      s.per_point_times = cloud.has_times();
      if (cloud.has_times()) {
        const auto [lo, hi] = std::minmax_element(cloud.time.begin(), cloud.time.end());
        s.sweep_seconds = static_cast<double>(*hi - *lo);
      }
    }
  }
  s.scans_read = n;
  s.mean_points = n > 0 ? points / static_cast<double>(n) : 0.0;
  s.fields = info.point_fields;
  s.labels = info.has_labels;
  s.calibration = info.velo_to_cam.has_value();
  if (info.camera_poses) s.reference_poses = info.camera_poses->size();
  s.notes = info.notes;
  return s;
}

}  // namespace saloam
