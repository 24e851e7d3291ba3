#include "saloam/core/profiling.hpp"

#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <numeric>

namespace saloam {

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

StageTimer::StageTimer() : wall_start_(std::chrono::steady_clock::now()), cpu_start_ms_(thread_cpu_ms()) {}

StageTime StageTimer::lap() {
  const auto wall_now = std::chrono::steady_clock::now();
  const double cpu_now = thread_cpu_ms();
  const StageTime time{std::chrono::duration<double, std::milli>(wall_now - wall_start_).count(), cpu_now - cpu_start_ms_};
  wall_start_ = wall_now;
  cpu_start_ms_ = cpu_now;
  return time;
}

double StageTimer::elapsed_ms() const {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall_start_).count();
}

Summary summarize(std::vector<double> values) {
  Summary s;
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  s.median = values[n / 2];
  s.p95 = values[std::min(n - 1, n * 95 / 100)];
  s.sum = std::accumulate(values.begin(), values.end(), 0.0);
  s.mean = s.sum / static_cast<double>(n);
  s.max = values.back();
  return s;
}

}  // namespace saloam
