#include "saloam/runs/segmented_source.hpp"

#include <chrono>
#include <stdexcept>

namespace saloam {

SegmentedSource::SegmentedSource(FrameSource& inner, const std::function<std::unique_ptr<Segmenter>()>& make_segmenter,
                                 int workers, std::size_t lookahead)
    : inner_(inner), lookahead_(std::max<std::size_t>(lookahead, 1)) {
  for (int w = 0; w < std::max(workers, 1); ++w) segmenters_.push_back(make_segmenter());
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
    std::unique_lock lock(mutex_);
    room_.wait(lock, [&] {
      return stopping_ || error_ || next_read_ >= inner_.size() || (started_ && next_read_ < next_out_ + lookahead_);
    });
    if (stopping_ || error_ || next_read_ >= inner_.size()) return;
    const std::size_t k = next_read_++;
    try {
      LabelledCloud cloud = inner_.scan(k);  // under the lock: the inner source serves its frames in order
      lock.unlock();
      const auto start = std::chrono::steady_clock::now();
      cloud.label = segmenter.labels(cloud);
      cloud.instance.assign(cloud.size(), 0);
      cloud.has_labels = true;
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      lock.lock();
      done_.emplace(k, std::make_pair(std::move(cloud), ms));
    } catch (...) {
      if (!lock.owns_lock()) lock.lock();
      error_ = std::current_exception();
    }
    ready_.notify_all();
    room_.notify_all();
  }
}

LabelledCloud SegmentedSource::scan(std::size_t i) {
  std::unique_lock lock(mutex_);
  if (!started_) {
    started_ = true;
    next_read_ = next_out_ = i;
    room_.notify_all();
  }
  if (i != next_out_) throw std::logic_error("SegmentedSource: frames are served once, in order");
  ready_.wait(lock, [&] { return done_.count(i) > 0 || error_; });
  if (const auto it = done_.find(i); it == done_.end()) std::rethrow_exception(error_);
  auto node = done_.extract(i);
  served_ms_.push_back(node.mapped().second);
  ++next_out_;
  room_.notify_all();
  return std::move(node.mapped().first);
}

std::vector<double> SegmentedSource::segment_ms() const {
  const std::lock_guard lock(mutex_);
  return served_ms_;
}

}  // namespace saloam
