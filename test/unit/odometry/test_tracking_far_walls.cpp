// No runaway on far walls: a hand-held camera looks into a room's corner from 3 m, so the view is
// mostly two walls at 3-4.5 m (Kinect v1 depth noise of several cm there, harsh model) and the
// floor, at full rate (about 1 cm per frame). Once, frame-to-keyframe ICP from the
// constant-velocity prior estimated 15-17 cm steps against 1.2 cm of true motion in such a view,
// status ok, and the prior carried the error on (issue 12). Here: ok never comes with a step error
// above 2 cm, and the trajectory stays on the truth (ATE bound).
#include <gtest/gtest.h>

#include <string>

#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/synthetic_frame_source.h"
#include "tracking_run.h"

namespace quadric_slam {
namespace {

const std::string kScene = std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/far_walls.yaml";

test::TrackingRun runFarWalls(const OdometryTracker::Params& odometry, Trajectory* truth) {
  SyntheticFrameSource::Params source_params;
  source_params.rate = 30.0;
  source_params.seconds = 8.0;
  source_params.seed = 7;
  source_params.rgb = false;
  SyntheticFrameSource source(readSceneYaml(kScene), source_params);
  *truth = source.groundTruth();
  SlamParams params = loadSlamParams(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config");
  params.odometry = odometry;
  return test::runTracker(source, *truth, params, 1, 1000);
}

OdometryTracker::Params shippedOdometry() {
  return loadSlamParams(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config").odometry;
}

TEST(TrackingFarWalls, OkNeverComesWithAStepErrorAbove2cmAndNoRunaway) {
  Trajectory truth;
  const test::TrackingRun run = runFarWalls(shippedOdometry(), &truth);
  test::writeTrackingCsv(run, "far_walls");
  ASSERT_GE(run.frames.size(), 200u);
  EXPECT_LE(run.worstOkTranslation(), 0.02);
  EXPECT_GE(run.ok, 0.8 * run.frames.size())
      << "ok " << run.ok << " degenerate " << run.degenerate << " lost " << run.lost;
  // No runaway: the runaway reached metres. Measured 7.6 cm over the 8 s (each step within 1.3 cm;
  // the far walls leave a slow drift).
  EXPECT_LT(test::ateRmse(run, truth), 0.12);
}

// The prior cannot carry an unconfirmed velocity on: after a true 15 cm step between two frames
// (velocity 15 cm per frame) the camera stops; the constant-velocity prediction is then 15 cm off
// with the far walls in view. The tracker must come back to the truth (ok, within 2 cm), not
// converge short of the prediction.
TEST(TrackingFarWalls, AVelocityTheDataDoNotConfirmIsNotCarriedOn) {
  SyntheticFrameSource::Params source_params;
  source_params.rate = 30.0;
  source_params.seconds = 1.0;
  source_params.seed = 11;
  source_params.rgb = false;
  SyntheticFrameSource source(readSceneYaml(kScene), source_params);
  const SlamParams params = loadSlamParams(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config");
  const NormalEstimator normals(params.normals);
  const QuadricSegmenter segmenter(params.segmentation);
  // Frames 0, 14 and 15 of the walk, given at consecutive 30 Hz stamps.
  std::vector<pcl::PointCloud<pcl::PointNormal>> clouds;
  std::vector<std::vector<QuadricMeasurement>> observations;
  std::vector<Eigen::Isometry3d> truth;
  RgbdFrame frame;
  CameraIntrinsics intrinsics;
  for (int k = 0; k <= 15 && source.next(frame); ++k) {
    if (k != 0 && k != 14 && k != 15)
      continue;
    clouds.emplace_back();
    normals.compute(
        backProject(depthViewOf(frame.depth_m), frame.intrinsics, params.back_projection),
        clouds.back());
    observations.push_back(
        toFrameMeasurements(segmenter.segment(clouds.back()), frame.stamp, frame.frame_id)
            .observations);
    OdometryTracker(params.odometry).adoptSurfaceNormals(observations.back(), clouds.back());
    truth.push_back(source.groundTruth()[k].T_world_sensor);
    intrinsics = frame.intrinsics;
  }
  ASSERT_EQ(clouds.size(), 3u);
  const double first_step = (truth[0].inverse() * truth[1]).translation().norm();
  ASSERT_GT(first_step, 0.08) << "the walk must make a large first step";
  OdometryTracker tracker(params.odometry);
  const double t0 = 100.0, dt = 1.0 / 30.0;
  tracker.track(clouds[0], intrinsics, t0, &observations[0]);
  const OdometryTracker::Result jump =
      tracker.track(clouds[1], intrinsics, t0 + dt, &observations[1]);
  ASSERT_EQ(jump.status, TrackingStatus::kOk) << jump.icp.message;
  const Eigen::Isometry3d true_jump = truth[0].inverse() * truth[1];
  ASSERT_LT((jump.T_odom_camera.inverse() * true_jump).translation().norm(), 0.02);
  // The camera now moves about 1 cm; the prior says another step as large as the first.
  const OdometryTracker::Result stop =
      tracker.track(clouds[2], intrinsics, t0 + 2 * dt, &observations[2]);
  const Eigen::Isometry3d true_stop = truth[0].inverse() * truth[2];
  const double error = (stop.T_odom_camera.inverse() * true_stop).translation().norm();
  EXPECT_EQ(stop.status, TrackingStatus::kOk) << stop.icp.message;
  EXPECT_LT(error, 0.02) << "started from the last pose: " << stop.started_from_last_pose;
}

}  // namespace
}  // namespace quadric_slam
