#include <gtest/gtest.h>

#include <stdexcept>

#include "quadric_slam/eval/recent_durations.h"

namespace qs = quadric_slam;

TEST(RecentDurations, EmptyWindowSummarisesToZero) {
  const qs::RecentDurations durations(10);
  const qs::TimingSummary s = durations.summary();
  EXPECT_EQ(s.count, 0u);
  EXPECT_DOUBLE_EQ(s.median_ms, 0.0);
  EXPECT_DOUBLE_EQ(s.p95_ms, 0.0);
  EXPECT_EQ(durations.total(), 0u);
}

TEST(RecentDurations, BeforeTheWindowFillsEveryDurationCounts) {
  qs::RecentDurations durations(300);
  for (int i = 1; i <= 100; ++i)
    durations.add(i);
  const qs::TimingSummary s = durations.summary();
  EXPECT_EQ(s.count, 100u);
  EXPECT_DOUBLE_EQ(s.median_ms, 50.0);
  EXPECT_DOUBLE_EQ(s.p95_ms, 95.0);
  EXPECT_DOUBLE_EQ(s.max_ms, 100.0);
  EXPECT_EQ(durations.total(), 100u);
}

TEST(RecentDurations, OnlyTheLatestDurationsAreSummarised) {
  // 1000 slow frames, then 100 fast ones: a window of 100 sees only the fast ones.
  qs::RecentDurations durations(100);
  for (int i = 0; i < 1000; ++i)
    durations.add(500.0);
  for (int i = 1; i <= 100; ++i)
    durations.add(i);
  const qs::TimingSummary s = durations.summary();
  EXPECT_EQ(s.count, 100u);
  EXPECT_DOUBLE_EQ(s.median_ms, 50.0);
  EXPECT_DOUBLE_EQ(s.p95_ms, 95.0);
  EXPECT_DOUBLE_EQ(s.max_ms, 100.0);
  EXPECT_EQ(durations.total(), 1100u);
}

TEST(RecentDurations, TheWindowWrapsInArrivalOrder) {
  // Capacity 3: after 1..5 the window holds 3, 4, 5 (5 overwrote 2, 4 overwrote 1).
  qs::RecentDurations durations(3);
  for (int i = 1; i <= 5; ++i)
    durations.add(i);
  EXPECT_DOUBLE_EQ(durations.summary().mean_ms, 4.0);
  durations.add(100.0);  // overwrites 3
  EXPECT_DOUBLE_EQ(durations.summary().mean_ms, (4.0 + 5.0 + 100.0) / 3.0);
  EXPECT_DOUBLE_EQ(durations.summary().median_ms, 5.0);
}

TEST(RecentDurations, ClearForgetsEverything) {
  qs::RecentDurations durations(4);
  for (int i = 0; i < 10; ++i)
    durations.add(7.0);
  durations.clear();
  EXPECT_EQ(durations.summary().count, 0u);
  EXPECT_EQ(durations.total(), 0u);
  durations.add(2.0);
  EXPECT_DOUBLE_EQ(durations.summary().median_ms, 2.0);
}

TEST(RecentDurations, ZeroCapacityIsRefused) {
  EXPECT_THROW(qs::RecentDurations(0), std::invalid_argument);
}
