#include <gtest/gtest.h>

#include <thread>

#include "quadric_slam/eval/stage_timing.h"

namespace qs = quadric_slam;

TEST(StageTiming, PercentilesAreNearestRank) {
  std::vector<double> values;
  for (int i = 100; i >= 1; --i)
    values.push_back(i);
  EXPECT_DOUBLE_EQ(qs::percentile(values, 0.5), 50.0);
  EXPECT_DOUBLE_EQ(qs::percentile(values, 0.95), 95.0);
  EXPECT_DOUBLE_EQ(qs::percentile(values, 1.0), 100.0);
  EXPECT_DOUBLE_EQ(qs::percentile(values, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(qs::percentile({}, 0.5), 0.0);
  const qs::TimingSummary s = qs::summarize(values);
  EXPECT_EQ(s.count, 100u);
  EXPECT_DOUBLE_EQ(s.max_ms, 100.0);
  EXPECT_DOUBLE_EQ(s.mean_ms, 50.5);
}

TEST(StageTiming, TimerRecordsEachStageAndWritesJson) {
  qs::StageTimer timer;
  const int result = timer.time("sleep", [] {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    return 7;
  });
  EXPECT_EQ(result, 7);
  timer.add("odometry", 3.0);
  timer.add("odometry", 5.0);
  const auto summaries = timer.summaries();
  ASSERT_EQ(summaries.size(), 2u);
  EXPECT_GE(summaries.at("sleep").max_ms, 5.0);
  EXPECT_EQ(summaries.at("odometry").count, 2u);
  const std::string json = timer.json(2, 1.5);
  EXPECT_NE(json.find("\"frames\": 2"), std::string::npos);
  EXPECT_NE(json.find("\"odometry\": {\"median_ms\": 3.000"), std::string::npos) << json;
  EXPECT_NE(json.find("\"wall_s\": 1.500"), std::string::npos);
}

TEST(StageTiming, ReservoirIsExactUpToItsCapacity) {
  qs::DurationReservoir reservoir(1000);
  for (int i = 1000; i >= 1; --i)
    reservoir.add(i);
  const qs::TimingSummary s = reservoir.summary();
  EXPECT_EQ(s.count, 1000u);
  EXPECT_DOUBLE_EQ(s.median_ms, 500.0);
  EXPECT_DOUBLE_EQ(s.p95_ms, 950.0);
  EXPECT_DOUBLE_EQ(s.max_ms, 1000.0);
  EXPECT_DOUBLE_EQ(s.mean_ms, 500.5);
}

TEST(StageTiming, ReservoirStaysBoundedAndKeepsPercentilesOfLongRuns) {
  // An hour at 30 Hz is about 100,000 frames; the kept sample must not grow past the capacity and
  // its percentiles must stay those of all durations. The durations rise with the frame index, so a
  // sample biased to early or late frames would show in the median.
  qs::DurationReservoir reservoir(2000);
  const int n = 200000;
  for (int i = 1; i <= n; ++i)
    reservoir.add(i * 0.001);
  EXPECT_EQ(reservoir.sample().size(), 2000u);
  const qs::TimingSummary s = reservoir.summary();
  EXPECT_EQ(s.count, static_cast<std::size_t>(n));
  EXPECT_DOUBLE_EQ(s.max_ms, n * 0.001);
  EXPECT_NEAR(s.mean_ms, (n + 1) * 0.0005, 1e-6);
  // Sample of 2000: the standard error of a quantile's rank is sqrt(q (1-q) / 2000) < 1.2%.
  EXPECT_NEAR(s.median_ms, 100.0, 0.05 * 100.0);
  EXPECT_NEAR(s.p95_ms, 190.0, 0.02 * 190.0);
}

TEST(StageTiming, ReservoirMergeKeepsExactCountsAndMax) {
  qs::DurationReservoir a(100), b(100);
  for (int i = 0; i < 500; ++i)
    a.add(1.0);
  for (int i = 0; i < 300; ++i)
    b.add(3.0);
  b.add(10.0);
  a.merge(b);
  const qs::TimingSummary s = a.summary();
  EXPECT_EQ(s.count, 801u);
  EXPECT_DOUBLE_EQ(s.max_ms, 10.0);
  EXPECT_NEAR(s.mean_ms, (500.0 + 900.0 + 10.0) / 801.0, 1e-12);
  EXPECT_EQ(a.sample().size(), 100u);
}
