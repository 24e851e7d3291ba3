#include "saloam/runs/frame_source.hpp"

#include <chrono>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/scan_io.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace saloam {

// ---- SequenceFolderSource ----

std::optional<Pose> SequenceFolderSource::velo_to_cam() const {
  if (!reader_.has_calib()) return std::nullopt;
  return reader_.velo_to_cam();
}

std::optional<std::vector<Pose>> SequenceFolderSource::camera_poses() const {
  if (!reader_.has_poses()) return std::nullopt;
  return reader_.camera_poses();
}

std::optional<std::vector<Pose>> SequenceFolderSource::sensor_camera_poses() const {
  const auto file = reader_.root() / "poses_sensor.txt";
  if (!std::filesystem::exists(file)) return std::nullopt;
  std::vector<Pose> poses = read_kitti_poses(file);
  if (poses.size() != reader_.size()) {
    throw InputError(file, fmt::format("{} poses for {} scans", poses.size(), reader_.size()));
  }
  return poses;
}

// ---- SimulatedSource ----

SimulatedSource::SimulatedSource(const SimulatedSequence& sequence, std::size_t lookahead,
                                 std::optional<std::filesystem::path> keep_folder)
    : sequence_(sequence), lookahead_(std::max<std::size_t>(lookahead, 1)), keep_folder_(std::move(keep_folder)) {
  if (keep_folder_) {
    const SequenceWriter writer(*keep_folder_);
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
    } catch (const std::exception&) {
      // A destructor must not throw; the folder then keeps all poses (still readable).
    }
  }
}

std::string SimulatedSource::name() const {
  const auto& o = sequence_.options();
  return o.camera_poses.empty() ? fmt::format("simulated '{}' route", o.preset) : "simulated trajectory";
}

std::optional<std::vector<Pose>> SimulatedSource::sensor_camera_poses() const {
  const auto& given = sequence_.camera_poses();
  const auto& sensor = sequence_.sensor_camera_poses();
  for (std::size_t i = 0; i < given.size(); ++i) {
    if ((given[i].translation() - sensor[i].translation()).norm() > 1e-9) return sensor;
  }
  return std::nullopt;
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
    throw std::logic_error(fmt::format("{}: frame {} asked for, but a stream serves frame {} next", name(), i, next_));
  }
  frame_ready_.wait(lock, [&] { return !queue_.empty() || stopping_; });
  if (queue_.empty()) {
    if (error_) std::rethrow_exception(error_);
    throw std::runtime_error(fmt::format("{}: the simulation stopped before frame {}", name(), i));
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
  if (sensor_camera_poses()) write_kitti_poses(*keep_folder_ / "poses_sensor.txt", first(sequence_.sensor_camera_poses()));
}

}  // namespace saloam
