// Honest tracking status on real Kinect frames: the 7-Scenes kitchen (KinectFusion ground truth)
// taken at every 10th and every 20th frame (about 7 and 15 cm, 3 and 7 degrees per step). The
// tracker may say lost, but it must never say ok on a step that is off by more than 5 cm or
// 5 degrees against the truth (issue 12).
#include <gtest/gtest.h>

#include <string>

#include "../test_data.h"
#include "kitchen_tracking.h"
#include "tracking_run.h"

namespace quadric_slam {
namespace {

SlamParams shippedParams() {
  return loadSlamParams(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config");
}

void expectHonest(const test::TrackingRun& run, double min_ok_share, const std::string& name) {
  test::writeTrackingCsv(run, name);
  EXPECT_LE(run.worstOkTranslation(), 0.05) << name;
  EXPECT_LE(run.worstOkRotationDeg(), 5.0) << name;
  // Honesty by saying lost everywhere would pass the two checks above; the tracker must still
  // track most of the sequence.
  EXPECT_GE(run.ok, min_ok_share * run.frames.size())
      << name << ": ok " << run.ok << " degenerate " << run.degenerate << " lost " << run.lost;
}

TEST(TrackingHonestyKitchen, EveryTwentiethFrameIsNeverOkOnAWrongStep) {
  QS_SKIP_WITHOUT_SHARED_DATA(test::sharedData(test::kKitchen), test::kResearchUseOnly);
  const test::TrackingRun run = test::runKitchen(20, 50, shippedParams());
  expectHonest(run, 0.8, "kitchen_every20");
}

TEST(TrackingHonestyKitchen, EveryTenthFrameIsNeverOkOnAWrongStep) {
  QS_SKIP_WITHOUT_SHARED_DATA(test::sharedData(test::kKitchen), test::kResearchUseOnly);
  const test::TrackingRun run = test::runKitchen(10, 60, shippedParams());
  expectHonest(run, 0.9, "kitchen_every10");
}

// Not a check: writes, with QS_TRACKING_CSV_DIR set, the per-frame criterion (inlier share of the
// overlapping points, residual RMS) beside the step error with the acceptance thresholds switched
// off, at full rate and every 10th and 20th frame; the thresholds in config/odometry.yaml were read
// off these files. Run with --gtest_also_run_disabled_tests.
TEST(TrackingHonestyKitchen, DISABLED_RecordCriterionWithoutThresholds) {
  QS_SKIP_WITHOUT_SHARED_DATA(test::sharedData(test::kKitchen), test::kResearchUseOnly);
  SlamParams params = shippedParams();
  params.odometry.icp.min_overlap_inlier_fraction = 0.0;
  params.odometry.icp.max_rms_residual = 1.0;
  for (const int every : {1, 10, 20})
    test::writeTrackingCsv(test::runKitchen(every, every == 1 ? 1000 : 1000 / every, params),
                           "kitchen_criterion_every" + std::to_string(every));
}

}  // namespace
}  // namespace quadric_slam
