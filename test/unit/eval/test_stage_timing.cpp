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
