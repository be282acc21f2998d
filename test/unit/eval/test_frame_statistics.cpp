#include <gtest/gtest.h>

#include <string>

#include "quadric_slam/eval/frame_statistics.h"

namespace qs = quadric_slam;

TEST(FrameStatistics, CountsProcessedAndDroppedFramesAsReceived) {
  qs::FrameStatistics stats;
  for (int i = 1; i <= 20; ++i)
    stats.processed(i);
  stats.dropped("no camera_info yet");
  stats.dropped("no camera_info yet");
  stats.dropped("size mismatch");
  EXPECT_EQ(stats.processedCount(), 20u);
  EXPECT_EQ(stats.droppedCount(), 3u);
  EXPECT_EQ(stats.received(), 23u);
  EXPECT_EQ(stats.lastDropReason(), "size mismatch");
  ASSERT_EQ(stats.dropsPerReason().size(), 2u);
  EXPECT_EQ(stats.dropsPerReason().at("no camera_info yet"), 2u);
  EXPECT_EQ(stats.dropsPerReason().at("size mismatch"), 1u);
  EXPECT_EQ(stats.timing().count, 20u);
  EXPECT_DOUBLE_EQ(stats.timing().median_ms, 10.0);
  EXPECT_DOUBLE_EQ(stats.timing().p95_ms, 19.0);
}

TEST(FrameStatistics, TimingCoversTheRecentWindowOnly) {
  qs::FrameStatistics stats(/*timing_window=*/10);
  for (int i = 0; i < 50; ++i)
    stats.processed(1000.0);
  for (int i = 0; i < 10; ++i)
    stats.processed(5.0);
  EXPECT_EQ(stats.processedCount(), 60u);
  EXPECT_EQ(stats.timing().count, 10u);
  EXPECT_DOUBLE_EQ(stats.timing().p95_ms, 5.0);
}

TEST(FrameStatistics, DistinctReasonsAreBounded) {
  // Reasons with frame-specific text must not grow the map without bound.
  qs::FrameStatistics stats(300, /*max_reasons=*/3);
  for (int i = 0; i < 100; ++i)
    stats.dropped("bad stamp " + std::to_string(i));
  EXPECT_EQ(stats.droppedCount(), 100u);
  EXPECT_EQ(stats.dropsPerReason().size(), 4u);  // three kept apart + the rest together
  EXPECT_EQ(stats.dropsPerReason().at("bad stamp 0"), 1u);
  EXPECT_EQ(stats.dropsPerReason().at(qs::FrameStatistics::kOtherReasons), 97u);
  // A reason already held keeps its own count.
  stats.dropped("bad stamp 1");
  EXPECT_EQ(stats.dropsPerReason().at("bad stamp 1"), 2u);
  EXPECT_EQ(stats.lastDropReason(), "bad stamp 1");
}

TEST(FrameStatistics, PeriodsCountSinceThePreviousReport) {
  qs::FrameStatistics stats;
  stats.processed(1.0);
  stats.processed(1.0);
  stats.dropped("x");
  qs::FrameStatistics::Period period = stats.takePeriod();
  EXPECT_EQ(period.processed, 2u);
  EXPECT_EQ(period.dropped, 1u);
  period = stats.takePeriod();
  EXPECT_EQ(period.processed, 0u);
  EXPECT_EQ(period.dropped, 0u);
  stats.dropped("y");
  period = stats.takePeriod();
  EXPECT_EQ(period.processed, 0u);
  EXPECT_EQ(period.dropped, 1u);
}
