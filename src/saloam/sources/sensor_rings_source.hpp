#pragma once
// The sensor's laser count applied to the ring field: once a sensor profile
// is chosen (--sensor NAME, or guessed from the first scan), a point whose
// ring is at or beyond the profile's lasers fits no laser of the sensor. The
// stage drops such points and counts them with the readers' checks
// (io/point_checks.hpp): one warning per frame that had any, naming the
// source and frame as a reader's warning names its file; a frame left with
// no point is an InputError. Frames without a ring field pass as they are.

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saloam/io/frame_source.hpp"
#include "saloam/io/point_checks.hpp"

namespace saloam {

/// Drops the points of `cloud` whose ring is at or beyond `lasers` (cloud
/// with a ring field; else nothing), counting them in `counts`.
void drop_rings_beyond_sensor(LabelledCloud& cloud, std::size_t lasers, PointCheckCounts& counts);

class SensorRingsSource final : public FrameSource {
 public:
  /// `lasers` > 0: the sensor profile's laser count (the whole profile's,
  /// also when only some of its lasers are in the scans).
  SensorRingsSource(std::unique_ptr<FrameSource> inner, std::size_t lasers);

  [[nodiscard]] const SourceInfo& info() const override { return inner_->info(); }
  LabelledCloud scan(std::size_t i) override;
  std::optional<SourceFrame> next_frame(std::size_t i) override;
  [[nodiscard]] std::vector<SourceStageTimes> stage_times() const override { return inner_->stage_times(); }
  [[nodiscard]] std::optional<StreamStats> stream_stats() const override { return inner_->stream_stats(); }
  void close_stream() override { inner_->close_stream(); }

  /// Points dropped so far, over every frame served.
  [[nodiscard]] std::size_t dropped() const { return dropped_; }

 private:
  void check(LabelledCloud& cloud, std::size_t i);

  std::unique_ptr<FrameSource> inner_;
  std::size_t lasers_ = 0;
  std::size_t dropped_ = 0;
};

}  // namespace saloam
