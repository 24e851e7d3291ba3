#include <gtest/gtest.h>

#include <cmath>
#include <thread>
#include <vector>

#include "saloam/core/profiling.hpp"

namespace saloam {
namespace {

TEST(Profiling, SummarizesPerFrameValues) {
  std::vector<double> values;
  for (int i = 100; i >= 1; --i) values.push_back(i);  // 1 .. 100, unsorted
  const Summary s = summarize(values);
  EXPECT_DOUBLE_EQ(s.median, 51.0);  // the upper median, element n/2 in sorted order
  EXPECT_DOUBLE_EQ(s.p95, 96.0);     // element 95 n / 100
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_DOUBLE_EQ(s.max, 100.0);
  EXPECT_DOUBLE_EQ(s.sum, 5050.0);
  const Summary one = summarize({7.0});
  EXPECT_DOUBLE_EQ(one.median, 7.0);
  EXPECT_DOUBLE_EQ(one.p95, 7.0);
  const Summary none = summarize({});
  EXPECT_EQ(none.median, 0.0);
  EXPECT_EQ(none.max, 0.0);
}

TEST(Profiling, StageTimerSeparatesWallTimeFromTheThreadsCpuTime) {
  StageTimer timer;
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // wall time, no CPU time
  const StageTime sleeping = timer.lap();
  EXPECT_GE(sleeping.wall_ms, 19.0);
  EXPECT_LT(sleeping.cpu_ms, 10.0);
  volatile double sink = 0;
  const double start = thread_cpu_ms();
  while (thread_cpu_ms() - start < 20.0) sink = sink + std::sqrt(sink + 1.0);  // CPU time
  const StageTime working = timer.lap();  // only the time since the previous lap
  EXPECT_GE(working.cpu_ms, 19.0);
  EXPECT_GE(working.wall_ms, working.cpu_ms - 1.0);
  EXPECT_LT(working.wall_ms, sleeping.wall_ms + working.cpu_ms + 1000.0);
  EXPECT_GE(timer.elapsed_ms(), 0.0);
}

TEST(Profiling, PeakMemoryIsPositiveAndNeverShrinks) {
  const double before = peak_rss_mib();
  EXPECT_GT(before, 0.0);
  {
    std::vector<char> block(64u << 20, 1);  // 64 MiB touched
    EXPECT_GT(peak_rss_mib(), before + 32.0);
    EXPECT_EQ(block[block.size() / 2], 1);
  }
  EXPECT_GE(peak_rss_mib(), before + 32.0);
}

TEST(Profiling, ColumnTakesOneStageFromEveryFrame) {
  struct Row {
    double a = 0, b = 0;
    [[nodiscard]] double total() const { return a + b; }
  };
  const std::vector<Row> rows{{1, 2}, {3, 4}};
  EXPECT_EQ(column(rows, &Row::b), (std::vector<double>{2, 4}));
  EXPECT_EQ(column(rows, &Row::total), (std::vector<double>{3, 7}));
}

}  // namespace
}  // namespace saloam
