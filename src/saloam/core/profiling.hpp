#pragma once
// Measuring the system from outside its algorithms: a stage timer (wall
// clock and the calling thread's CPU time), the peak memory of the process,
// and the summary of per-frame times every report prints. Timings never
// change a result.

#include <chrono>
#include <functional>
#include <vector>

namespace saloam {

/// CPU time of the calling thread [ms]. On a shared machine wall time includes
/// waiting for a core; a single-threaded stage's CPU time is its cost.
double thread_cpu_ms();

/// The most memory the process has held so far [MiB] (max resident set, getrusage).
double peak_rss_mib();

/// Wall and CPU time of one stage [ms].
struct StageTime {
  double wall_ms = 0;
  double cpu_ms = 0;
};

/// Times consecutive stages: each lap() returns the time since the previous
/// lap (or the construction) and starts the next stage. CPU time is the
/// calling thread's: workers of a parallel stage are not counted.
class StageTimer {
 public:
  StageTimer();
  StageTime lap();
  /// Wall time since the previous lap or the construction [ms], without ending the stage.
  [[nodiscard]] double elapsed_ms() const;
  /// The same in seconds.
  [[nodiscard]] double elapsed_s() const { return elapsed_ms() / 1000.0; }

 private:
  std::chrono::steady_clock::time_point wall_start_;
  double cpu_start_ms_;
};

/// Per-frame values (times [ms]) summarised: the upper median (element n/2
/// in sorted order), the 95th percentile (element 95 n / 100), mean, max and
/// sum; all 0 for no values.
struct Summary {
  double median = 0, p95 = 0, mean = 0, max = 0, sum = 0;
};
Summary summarize(std::vector<double> values);

/// One stage's times over the frames: get(row) for each per-frame row (a
/// member pointer such as &FrameTimings::features_ms, or &FrameTimings::total_ms).
template <class Row, class Get>
std::vector<double> column(const std::vector<Row>& rows, Get get) {
  std::vector<double> values;
  values.reserve(rows.size());
  for (const Row& row : rows) values.push_back(std::invoke(get, row));
  return values;
}

}  // namespace saloam
