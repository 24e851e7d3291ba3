#pragma once
// Cooperative cancellation: the CLI sets the flag on SIGINT/SIGTERM; long
// loops check it, stop cleanly and keep what they have written.

#include <atomic>

namespace saloam {

inline std::atomic<bool>& stop_flag() {
  static std::atomic<bool> flag{false};
  return flag;
}
inline bool stop_requested() { return stop_flag().load(std::memory_order_relaxed); }
inline void request_stop() { stop_flag().store(true, std::memory_order_relaxed); }
/// The stop taken as handled (a live run, which Ctrl-C ends as the end of a
/// file ends a recorded one, finishing its outputs); a later Ctrl-C stops again.
inline void clear_stop() { stop_flag().store(false, std::memory_order_relaxed); }

}  // namespace saloam
