#pragma once
// The bounded queue between a live source's receiver thread and the run:
// the receiver never waits for the run. When the run falls behind and the
// queue is full, the oldest queued frame is dropped, whole (a frame is
// queued only once complete, so none is ever cut), and counted: the run then
// goes on with the newest frames, its poses about the present rather than
// ever later behind the sensor. Thread-safe.

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <string>

#include "saloam/io/frame_source.hpp"

namespace saloam {

/// A frame waiting for the run, and when its last packet came.
struct QueuedFrame {
  SourceFrame frame;
  std::chrono::steady_clock::time_point completed;
};

class FrameQueue {
 public:
  /// Holds at most `capacity` frames (at least 1).
  explicit FrameQueue(std::size_t capacity);

  /// Queues a frame (the receiver's side; never waits); when full, the oldest is dropped and counted.
  void push(QueuedFrame frame);
  /// No frame will come any more: `reason` ("idle for 2 s", ...); waiting pops return.
  void end(std::string reason);
  /// The oldest queued frame, waiting for one; none once the stream ended and the queue is empty.
  std::optional<QueuedFrame> pop();

  [[nodiscard]] std::size_t dropped() const;
  [[nodiscard]] std::size_t queued() const;
  /// Why the stream ended; empty while it runs.
  [[nodiscard]] std::string ended_by() const;

 private:
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<QueuedFrame> frames_;
  std::size_t dropped_ = 0;
  bool ended_ = false;
  std::string ended_by_;
};

}  // namespace saloam
