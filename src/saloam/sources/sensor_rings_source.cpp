#include "saloam/sources/sensor_rings_source.hpp"

#include <utility>

#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace saloam {

void drop_rings_beyond_sensor(LabelledCloud& cloud, std::size_t lasers, PointCheckCounts& counts) {
  if (!cloud.has_rings()) return;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) kept += keep_sensor_ring(cloud.ring[i], lasers, counts) ? 1 : 0;
  if (kept == cloud.size()) return;
  LabelledCloud out;
  out.has_labels = cloud.has_labels;
  out.reserve(kept);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (cloud.ring[i] < lasers) out.push_back_from(cloud, i);
  }
  cloud = std::move(out);
}

SensorRingsSource::SensorRingsSource(std::unique_ptr<FrameSource> inner, std::size_t lasers)
    : inner_(std::move(inner)), lasers_(lasers) {}

void SensorRingsSource::check(LabelledCloud& cloud, std::size_t i) {
  const std::size_t points = cloud.size();
  PointCheckCounts counts;
  drop_rings_beyond_sensor(cloud, lasers_, counts);
  if (counts.ring_beyond_sensor == 0) return;
  dropped_ += counts.ring_beyond_sensor;
  const std::string where = fmt::format("{}, frame {}", inner_->info().name, inner_->info().first_frame + i);
  if (cloud.empty()) {
    throw InputError(where, fmt::format("every one of its {} points has a ring at or beyond the sensor's {} lasers "
                                        "(0..{}): not this sensor's scan (--sensor NAME chooses the profile)",
                                        points, lasers_, lasers_ - 1));
  }
  warn_point_checks(where, points, counts);
}

LabelledCloud SensorRingsSource::scan(std::size_t i) {
  LabelledCloud cloud = inner_->scan(i);
  check(cloud, i);
  return cloud;
}

std::optional<SourceFrame> SensorRingsSource::next_frame(std::size_t i) {
  auto frame = inner_->next_frame(i);
  if (frame) check(frame->cloud, i);
  return frame;
}

}  // namespace saloam
