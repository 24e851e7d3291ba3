#pragma once
// The odometry's one parallel loop shape.

#include <cstddef>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace saloam {

/// Calls body(i) for every i in [0, n): with `parallel` and more than two
/// blocks of work, in blocks of `grain` indices over the TBB threads, else in
/// order. A body writes only index i's results, so the output does not
/// depend on the number of threads.
template <class Body>
void for_each_index(std::size_t n, bool parallel, std::size_t grain, Body&& body) {
  if (parallel && n > 2 * grain) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
    });
  } else {
    for (std::size_t i = 0; i < n; ++i) body(i);
  }
}

}  // namespace saloam
