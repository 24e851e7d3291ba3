#include "saloam/viewer/live_view.hpp"

#include <stdexcept>

#include <nlohmann/json.hpp>

#include "saloam/viewer/point_encoding.hpp"

namespace saloam {

namespace {

const char* status_name(LiveRunStatus status) {
  switch (status) {
    case LiveRunStatus::kRunning: return "running";
    case LiveRunStatus::kFinished: return "finished";
    case LiveRunStatus::kInterrupted: return "interrupted";
    case LiveRunStatus::kFailed: return "failed";
  }
  return "unknown";
}

void append_u32(std::string& out, std::uint32_t value) {
  for (int byte = 0; byte < 4; ++byte) out.push_back(static_cast<char>((value >> (8 * byte)) & 0xFFU));
}

/// Every k-th point, at most `budget` of them: cheap enough for the run's
/// thread (a shuffled subset, as the static page's, took twice as long: bench_viewer).
LabelledCloud strided_subset(const LabelledCloud& cloud, std::size_t budget) {
  LabelledCloud subset;
  subset.has_labels = cloud.has_labels;
  if (budget == 0) return subset;
  const std::size_t step = (cloud.size() + budget - 1) / budget;
  for (std::size_t i = 0; i < cloud.size(); i += std::max<std::size_t>(step, 1)) subset.push_back_from(cloud, i);
  return subset;
}

}  // namespace

LiveView::LiveView(std::string title, std::string command, const LiveViewOptions& options)
    : title_(std::move(title)), command_(std::move(command)), options_(options), spacing_(options.chunk_spacing) {
  if (!(options.chunk_spacing > 0)) throw std::invalid_argument("LiveViewOptions::chunk_spacing must be positive");
}

// Only the run's thread adds: it reads its own state without the lock and
// takes the lock only to change what the server's threads read.
bool LiveView::chunk_due(const Pose& pose) const {
  if (poses_.empty()) return true;
  const double step = (pose.translation() - poses_.back().translation()).norm();
  return travelled_ + step - chunk_travelled_ >= spacing_;
}

void LiveView::keep_chunk(std::size_t frame, const LabelledCloud& scan) {
  Chunk chunk{static_cast<std::uint32_t>(frame), encode_scan(strided_subset(scan, options_.points_per_chunk))};
  const std::size_t points = chunk.points.size() / 7;
  const std::lock_guard lock(mutex_);
  chunks_.push_back(std::move(chunk));
  map_points_ += points;
  chunk_travelled_ = travelled_;
  // A long run keeps a thinner map rather than outgrowing the browser.
  while (map_points_ >= options_.max_map_points * static_cast<std::size_t>(spacing_ / options_.chunk_spacing)) {
    spacing_ *= 2;
  }
}

void LiveView::add_frame(const Pose& pose, const LabelledCloud& scan) {
  const bool due = chunk_due(pose);
  const std::size_t frame = poses_.size();
  std::string latest;
  append_u32(latest, static_cast<std::uint32_t>(frame));
  latest += encode_scan(strided_subset(scan, options_.scan_points));
  {
    const std::lock_guard lock(mutex_);
    if (!poses_.empty()) travelled_ += (pose.translation() - poses_.back().translation()).norm();
    poses_.push_back(pose);
    latest_scan_ = std::move(latest);
  }
  if (due) keep_chunk(frame, scan);
}

void LiveView::set_background(const LabelledCloud& map) {
  const MapQuantization quantization = map_quantization(map);
  std::string bytes = encode_map(map, quantization);
  const std::lock_guard lock(mutex_);
  background_ = std::move(bytes);
  background_origin_ = {quantization.origin.x(), quantization.origin.y(), quantization.origin.z()};
  background_scale_ = quantization.scale;
}

void LiveView::replace_poses(std::vector<Pose> poses) {
  const std::lock_guard lock(mutex_);
  if (poses.size() != poses_.size()) throw std::invalid_argument("LiveView::replace_poses: one pose per frame added");
  poses_ = std::move(poses);
  ++revision_;
}

void LiveView::add_loop(std::size_t query, std::size_t match) {
  const std::lock_guard lock(mutex_);
  loops_.emplace_back(query, match);
}

void LiveView::finish(LiveRunStatus status) {
  const std::lock_guard lock(mutex_);
  status_ = status;
}

std::string LiveView::state_json(std::uint64_t revision, std::size_t known_frames) const {
  const std::lock_guard lock(mutex_);
  const std::size_t first = revision == revision_ ? std::min(known_frames, poses_.size()) : 0;
  nlohmann::json loops = nlohmann::json::array();
  for (const auto& [query, match] : loops_) loops.push_back({query, match});
  nlohmann::json background = nullptr;
  if (!background_.empty()) {
    background = {{"points", background_.size() / 7}, {"origin", background_origin_}, {"scale", background_scale_}};
  }
  const nlohmann::json state{{"title", title_},
                             {"command", command_},
                             {"status", status_name(status_)},
                             {"revision", revision_},
                             {"frames", poses_.size()},
                             {"first", first},
                             {"poses", poses_base64(poses_, first)},
                             {"loops", loops},
                             {"chunks", chunks_.size()},
                             {"map_points", map_points_},
                             {"chunk_spacing", spacing_},
                             {"travelled", travelled_},
                             {"background", background}};
  return state.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string LiveView::map_chunks(std::size_t first) const {
  const std::lock_guard lock(mutex_);
  std::string out;
  for (std::size_t c = first; c < chunks_.size(); ++c) {
    append_u32(out, chunks_[c].frame);
    append_u32(out, static_cast<std::uint32_t>(chunks_[c].points.size() / 7));
    out += chunks_[c].points;
  }
  return out;
}

std::string LiveView::latest_scan() const {
  const std::lock_guard lock(mutex_);
  return latest_scan_;
}

std::string LiveView::background() const {
  const std::lock_guard lock(mutex_);
  return background_;
}

std::size_t LiveView::frames() const {
  const std::lock_guard lock(mutex_);
  return poses_.size();
}

std::size_t LiveView::chunks() const {
  const std::lock_guard lock(mutex_);
  return chunks_.size();
}

std::size_t LiveView::map_points() const {
  const std::lock_guard lock(mutex_);
  return map_points_;
}

LiveRunStatus LiveView::status() const {
  const std::lock_guard lock(mutex_);
  return status_;
}

}  // namespace saloam
