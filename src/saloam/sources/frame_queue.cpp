#include "saloam/sources/frame_queue.hpp"

#include <algorithm>

namespace saloam {

FrameQueue::FrameQueue(std::size_t capacity) : capacity_(std::max<std::size_t>(capacity, 1)) {}

void FrameQueue::push(QueuedFrame frame) {
  {
    const std::lock_guard lock(mutex_);
    if (frames_.size() >= capacity_) {
      frames_.pop_front();
      ++dropped_;
    }
    frames_.push_back(std::move(frame));
  }
  ready_.notify_one();
}

void FrameQueue::end(std::string reason) {
  {
    const std::lock_guard lock(mutex_);
    if (ended_) return;  // the first reason stands
    ended_ = true;
    ended_by_ = std::move(reason);
  }
  ready_.notify_all();
}

std::optional<QueuedFrame> FrameQueue::pop() {
  std::unique_lock lock(mutex_);
  ready_.wait(lock, [&] { return !frames_.empty() || ended_; });
  if (frames_.empty()) return std::nullopt;
  QueuedFrame out = std::move(frames_.front());
  frames_.pop_front();
  return out;
}

std::size_t FrameQueue::dropped() const {
  const std::lock_guard lock(mutex_);
  return dropped_;
}

std::size_t FrameQueue::queued() const {
  const std::lock_guard lock(mutex_);
  return frames_.size();
}

std::string FrameQueue::ended_by() const {
  const std::lock_guard lock(mutex_);
  return ended_by_;
}

}  // namespace saloam
