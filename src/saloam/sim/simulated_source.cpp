#include "saloam/sim/simulated_source.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "saloam/io/intensity_scale.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/sim/simulation_record.hpp"

namespace saloam {
namespace {

/// Where the scans were really taken, when that differs from the poses given.
std::optional<std::vector<Pose>> moved_sensor_poses(const SimulatedSequence& sequence) {
  const auto& given = sequence.camera_poses();
  const auto& sensor = sequence.sensor_camera_poses();
  for (std::size_t i = 0; i < given.size(); ++i) {
    if ((given[i].translation() - sensor[i].translation()).norm() > 1e-9) return sensor;
  }
  return std::nullopt;
}

SourceInfo simulated_info(const SimulatedSequence& sequence) {
  const auto& o = sequence.options();
  SourceInfo info;
  info.name = o.camera_poses.empty() ? fmt::format("simulated '{}' route", o.preset) : "simulated trajectory";
  info.times = sequence.times();
  info.has_labels = true;
  info.rereadable = false;
  info.velo_to_cam = sequence.velo_to_cam();
  info.camera_poses = sequence.camera_poses();
  info.sensor_camera_poses = moved_sensor_poses(sequence);
  info.format = "simulated";
  info.point_fields = "x y z remission";
  info.notes.push_back(IntensityScale{1.0F, "the simulator's remission"}.note());
  return info;
}

}  // namespace

SimulatedSource::SimulatedSource(const SimulatedSequence& sequence, std::size_t lookahead,
                                 std::optional<std::filesystem::path> keep_folder)
    : sequence_(sequence),
      info_(simulated_info(sequence)),
      lookahead_(std::max<std::size_t>(lookahead, 1)),
      keep_folder_(std::move(keep_folder)) {
  if (keep_folder_) {
    kept_.reset(new OutputFolder(open_sequence_output(*keep_folder_)));
    const SequenceWriter writer(*keep_folder_);
    write_simulation_record(*keep_folder_, sequence_.options());
    writer.write_calib(sequence_.velo_to_cam());
    writer.write_camera_poses(sequence_.camera_poses());
    writer.write_times(sequence_.times());
    if (sequence_.options().labels == LabelMode::kNoisy) std::filesystem::create_directories(*keep_folder_ / "labels_gt");
  }
  worker_ = std::thread([this] { render_ahead(); });
}

SimulatedSource::~SimulatedSource() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  slot_free_.notify_all();
  worker_.join();
  if (keep_folder_) {
    try {
      finish_kept_folder(rendered_);
      kept_->finish(rendered_ == sequence_.size() ? "complete" : "interrupted");
    } catch (const std::exception&) {
      // A destructor must not throw; the folder then keeps all poses (still readable) and its record says "failed".
    }
  }
}

void SimulatedSource::render_ahead() {
  for (std::size_t k = 0; k < sequence_.size(); ++k) {
    {
      std::unique_lock lock(mutex_);
      slot_free_.wait(lock, [&] { return stopping_ || queue_.size() < lookahead_; });
      if (stopping_) return;
    }
    try {
      SimulatedFrame frame = sequence_.render(k);
      if (keep_folder_) keep(k, frame);
      const std::lock_guard lock(mutex_);
      if (!frame.gt_labels.empty()) score_.add(frame.gt_labels, frame.cloud.label);
      queue_.push_back(std::move(frame.cloud));
      rendered_ = k + 1;
    } catch (...) {
      const std::lock_guard lock(mutex_);
      error_ = std::current_exception();
      break;
    }
    frame_ready_.notify_one();
  }
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;  // nothing more will come
  }
  frame_ready_.notify_all();
}

LabelledCloud SimulatedSource::scan(std::size_t i) {
  std::unique_lock lock(mutex_);
  if (i != next_) {
    throw std::logic_error(fmt::format("{}: frame {} asked for, but a stream serves frame {} next", info_.name, i, next_));
  }
  frame_ready_.wait(lock, [&] { return !queue_.empty() || stopping_; });
  if (queue_.empty()) {
    if (error_) std::rethrow_exception(error_);
    throw std::runtime_error(fmt::format("{}: the simulation stopped before frame {}", info_.name, i));
  }
  LabelledCloud cloud = std::move(queue_.front());
  queue_.pop_front();
  ++next_;
  lock.unlock();
  slot_free_.notify_one();
  return cloud;
}

SegmentationScore SimulatedSource::label_score() const {
  const std::lock_guard lock(mutex_);
  return score_;
}

std::size_t SimulatedSource::frames_rendered() const {
  const std::lock_guard lock(mutex_);
  return rendered_;
}

void SimulatedSource::keep(std::size_t k, const SimulatedFrame& frame) const {
  const SequenceWriter writer(*keep_folder_);
  writer.write_scan(k, frame.cloud);
  if (!frame.gt_labels.empty()) {
    write_scan_labels(*keep_folder_ / "labels_gt" / (frame_name(k) + ".label"), frame.gt_labels, frame.gt_instances);
  }
}

void SimulatedSource::finish_kept_folder(std::size_t frames) const {
  const SequenceWriter writer(*keep_folder_);
  const auto first = [&](const auto& all) {
    return std::vector(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(std::min(frames, all.size())));
  };
  if (frames < sequence_.size()) {
    writer.write_camera_poses(first(sequence_.camera_poses()));
    writer.write_times(first(sequence_.times()));
  }
  if (info_.sensor_camera_poses) write_kitti_poses(*keep_folder_ / "poses_sensor.txt", first(sequence_.sensor_camera_poses()));
}

}  // namespace saloam
