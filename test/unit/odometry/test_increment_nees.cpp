// Is the tracker's increment covariance honest on real and generated depth? The NEES (squared
// Mahalanobis distance of each frame-to-frame step's error against the truth under the reported
// increment covariance) of the steps reported ok: with a right covariance it is chi-square with 6
// degrees of freedom, median 5.35. ICP's raw sigma^2 H^-1 is far too confident on real depth
// (correlated noise, model error); config/odometry.yaml's increment_covariance_scale and floors
// were chosen from these runs (with QS_TRACKING_CSV_DIR set they write the per-frame values).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "../test_data.h"
#include "kitchen_tracking.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/synthetic_frame_source.h"
#include "tracking_run.h"

namespace quadric_slam {
namespace {

SlamParams shippedParams() {
  return loadSlamParams(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config");
}

double medianOkNees(const test::TrackingRun& run) {
  std::vector<double> nees;
  for (size_t i = 1; i < run.frames.size(); ++i)
    if (run.frames[i].status == TrackingStatus::kOk)
      nees.push_back(run.frames[i].increment_nees);
  if (nees.empty())
    return 0;
  std::nth_element(nees.begin(), nees.begin() + nees.size() / 2, nees.end());
  return nees[nees.size() / 2];
}

// The band [1.5, 12] around the chi-square median 5.35: a covariance more than about 3.5 times too
// large or 2.2 times too small leaves it. (Raw sigma^2 H^-1, increment_covariance_scale 1 and no
// floors, gives medians in the hundreds on the kitchen.) The lower bound was 2.5 until the ICP took
// the surfaces' normals (surface_normals): the generated desk's steps then came closer to its exact
// truth than the step-proportional floors assume (median 3.0 -> 1.9), while the kitchen's truth
// (KinectFusion) adds its own millimetre per frame to every step's error (7.9 and 7.8); no one
// scale and pair of floors centres both (config/odometry.yaml).
constexpr double kMinMedianNees = 1.5;
constexpr double kMaxMedianNees = 12.0;

TEST(IncrementNees, RealKitchenFullRate) {
  QS_SKIP_WITHOUT_SHARED_DATA(test::sharedData(test::kKitchen), test::kResearchUseOnly);
  const test::TrackingRun run = test::runKitchen(1, 300, shippedParams());
  test::writeTrackingCsv(run, "increment_kitchen_every1");
  const double median = medianOkNees(run);
  EXPECT_GT(median, kMinMedianNees);
  EXPECT_LT(median, kMaxMedianNees);
}

TEST(IncrementNees, RealKitchenEveryTenthFrame) {
  QS_SKIP_WITHOUT_SHARED_DATA(test::sharedData(test::kKitchen), test::kResearchUseOnly);
  const test::TrackingRun run = test::runKitchen(10, 60, shippedParams());
  test::writeTrackingCsv(run, "increment_kitchen_every10");
  const double median = medianOkNees(run);
  EXPECT_GT(median, kMinMedianNees);
  EXPECT_LT(median, kMaxMedianNees);
}

// Generated: the desk scene with the harsh Kinect model along the real fr1_desk trajectory at
// full rate (exact truth).
TEST(IncrementNees, GeneratedDeskFullRate) {
  const std::string trajectory = "tum_groundtruth/rgbd_dataset_freiburg1_desk-groundtruth.txt";
  QS_SKIP_WITHOUT_SHARED_DATA(test::sharedData(trajectory), test::kFullGroundTruth);
  const Scene scene =
      readSceneYaml(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/desk.yaml");
  SyntheticFrameSource::Params source_params;
  source_params.driving_trajectory = test::sharedData(trajectory).string();
  source_params.rate = 30.0;
  source_params.seconds = 6.0;
  source_params.seed = 5;
  source_params.rgb = false;
  SyntheticFrameSource source(scene, source_params);
  const Trajectory truth = source.groundTruth();
  const test::TrackingRun run = test::runTracker(source, truth, shippedParams(), 1, 1000);
  test::writeTrackingCsv(run, "increment_desk_every1");
  ASSERT_GE(run.frames.size(), 150u);
  const double median = medianOkNees(run);
  EXPECT_GT(median, kMinMedianNees);
  EXPECT_LT(median, kMaxMedianNees);
}

}  // namespace
}  // namespace quadric_slam
