#pragma once
// Parallel loop shapes (TBB) whose output does not depend on the number of
// threads: independent indices, and sums whose rounding is fixed. Header
// only; a module that includes it links TBB (scan, odometry).

#include <algorithm>
#include <cstddef>
#include <vector>

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

/// The sum of every index's term over [0, n): body(i, acc) adds index i's
/// term to acc. The indices go in fixed blocks of `block` (boundaries set by
/// n alone), each summed in index order from `zero` into its own
/// accumulator, with `parallel` over the TBB threads; the block sums are then
/// added in block order. Every addition happens in the same order whatever
/// the number of threads, so the result is bit-identical with one thread or
/// many. Acc needs `+=`.
template <class Acc, class Body>
Acc sum_in_blocks(std::size_t n, bool parallel, std::size_t block, const Acc& zero, Body&& body) {
  const std::size_t blocks = (n + block - 1) / block;
  std::vector<Acc> partial(blocks, zero);
  for_each_index(blocks, parallel, 1, [&](std::size_t b) {
    Acc acc = zero;
    const std::size_t end = std::min(n, (b + 1) * block);
    for (std::size_t i = b * block; i < end; ++i) body(i, acc);
    partial[b] = acc;
  });
  Acc total = zero;
  for (const Acc& p : partial) total += p;
  return total;
}

}  // namespace saloam
