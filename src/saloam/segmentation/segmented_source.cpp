#include "saloam/segmentation/segmented_source.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace saloam {

SegmentedSource::SegmentedSource(std::unique_ptr<FrameSource> inner, const SegmentationStageOptions& options)
    : SegmentedSource(
          std::move(inner), [&] { return std::make_unique<Segmenter>(options.model, options.plugin, options.rings); },
          options.workers, options.lookahead) {}

SegmentedSource::SegmentedSource(std::unique_ptr<FrameSource> inner,
                                 const std::function<std::unique_ptr<Segmenter>()>& make, int workers,
                                 std::size_t lookahead)
    : inner_(std::move(inner)), info_(inner_->info()), lookahead_(std::max<std::size_t>(lookahead, 1)) {
  info_.has_labels = true;
  info_.rereadable = false;
  for (int w = 0; w < std::max(workers, 1); ++w) segmenters_.push_back(make());
  for (const auto& segmenter : segmenters_) workers_.emplace_back([this, s = segmenter.get()] { work(*s); });
}

SegmentedSource::~SegmentedSource() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  room_.notify_all();
  for (auto& w : workers_) w.join();
}

void SegmentedSource::work(const Segmenter& segmenter) {
  for (;;) {
    // The reader's lock is held from taking a frame number to reading it, so
    // that frames leave the inner source in order while the network runs
    // unlocked; a live source may wait for its next frame meanwhile.
    std::unique_lock read(read_mutex_);
    std::unique_lock lock(mutex_);
    room_.wait(lock, [&] { return stopping_ || error_ || end_ || next_read_ < next_out_ + lookahead_; });
    if (stopping_ || error_ || end_) return;
    const std::size_t k = next_read_++;
    lock.unlock();
    try {
      std::optional<SourceFrame> frame = inner_->next_frame(k);
      read.unlock();
      if (!frame) {
        lock.lock();
        end_ = k;
      } else {
        StageTimer timer;
        frame->cloud.label = segmenter.labels(frame->cloud);
        frame->cloud.instance.assign(frame->cloud.size(), 0);
        frame->cloud.has_labels = true;
        const StageTime time = timer.lap();
        lock.lock();
        done_.emplace(k, std::make_pair(std::move(*frame), time));
      }
    } catch (...) {
      if (!lock.owns_lock()) lock.lock();
      error_ = std::current_exception();
    }
    ready_.notify_all();
    room_.notify_all();
  }
}

std::optional<SourceFrame> SegmentedSource::take(std::size_t i) {
  std::unique_lock lock(mutex_);
  if (i != next_out_)
    throw std::logic_error(fmt::format("{}: the segmentation stage serves frames once, in order (asked for {}, next is {})",
                                       info_.name, i, next_out_));
  ready_.wait(lock, [&] { return done_.count(i) > 0 || error_ || (end_ && *end_ <= i); });
  if (done_.count(i) == 0) {
    if (error_) std::rethrow_exception(error_);
    return std::nullopt;
  }
  auto node = done_.extract(i);
  served_.push_back(node.mapped().second);
  ++next_out_;
  room_.notify_all();
  return std::move(node.mapped().first);
}

LabelledCloud SegmentedSource::scan(std::size_t i) {
  std::optional<SourceFrame> frame = take(i);
  if (!frame) throw std::out_of_range(fmt::format("{}: frame {} is past the last frame", info_.name, i));
  return std::move(frame->cloud);
}

std::optional<SourceFrame> SegmentedSource::next_frame(std::size_t i) { return take(i); }

std::vector<SourceStageTimes> SegmentedSource::stage_times() const {
  auto times = inner_->stage_times();
  const std::lock_guard lock(mutex_);
  times.push_back({"segmentation", served_});
  return times;
}

}  // namespace saloam
