// Honest tracking status on sub-sampled sequences: scenes rendered with the harsh Kinect v1 model
// along the real fr1_desk (the desk scene) and fr1_room (a room around its path) hand-held
// trajectories, sampled at 3 Hz and 1.5 Hz
// (every 10th and every 20th frame of the 30 Hz recording: steps of up to 25 cm and 20 degrees).
// The tracker may say lost, but never ok on a step off by more than 5 cm or 5 degrees (issue 12).
#include <gtest/gtest.h>

#include <string>

#include "../test_data.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/synthetic_frame_source.h"
#include "tracking_run.h"

namespace quadric_slam {
namespace {

struct Case {
  const char* name;
  const char* scene;       // under config/scenes
  const char* trajectory;  // TUM ground truth driving the camera
  double rate;             // Hz: 3 = every 10th, 1.5 = every 20th frame of 30 Hz
  double seconds;
  double min_ok_share;  // the tracker must still track this share of the frames
};

test::TrackingRun runCase(const Case& c, Trajectory* truth) {
  const Scene scene =
      readSceneYaml(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/" + c.scene);
  SyntheticFrameSource::Params source_params;
  source_params.driving_trajectory = test::sharedData(c.trajectory).string();
  source_params.rate = c.rate;
  source_params.seconds = c.seconds;
  source_params.seed = 3;
  source_params.rgb = false;
  SyntheticFrameSource source(scene, source_params);
  *truth = source.groundTruth();
  return test::runTracker(
      source, *truth, loadSlamParams(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config"), 1, 1000);
}

class SubsampledSequence : public ::testing::TestWithParam<Case> {};

TEST_P(SubsampledSequence, OkNeverComesWithAStepErrorAbove5cmOr5Degrees) {
  const Case c = GetParam();
  QS_SKIP_WITHOUT_SHARED_DATA(test::sharedData(c.trajectory), test::kFullGroundTruth);
  Trajectory truth;
  const test::TrackingRun run = runCase(c, &truth);
  const std::string name = std::string(c.name) + "_" + std::to_string(int(c.rate * 10)) + "dhz";
  test::writeTrackingCsv(run, name);
  ASSERT_GE(run.frames.size(), 20u);
  EXPECT_LE(run.worstOkTranslation(), 0.05);
  EXPECT_LE(run.worstOkRotationDeg(), 5.0);
  EXPECT_GE(run.ok, c.min_ok_share * run.frames.size())
      << "ok " << run.ok << " degenerate " << run.degenerate << " lost " << run.lost;
}

INSTANTIATE_TEST_SUITE_P(
    Fr1Desk, SubsampledSequence,
    ::testing::Values(Case{"fr1_desk", "desk.yaml",
                           "tum_groundtruth/rgbd_dataset_freiburg1_desk-groundtruth.txt", 3.0, 20.0,
                           0.6},
                      Case{"fr1_desk", "desk.yaml",
                           "tum_groundtruth/rgbd_dataset_freiburg1_desk-groundtruth.txt", 1.5, 20.0,
                           0.4}));

// Known weak (issue 12, open). In the desk scene the fr1_room path turned away from everything; in
// the room around its path (room_fr1.yaml) the tracker says ok even at full rate on steps off by
// 5-18 cm (true steps 1-2 cm: 91 of 1466 steps, odometry ATE 88 cm) where a far wall or the floor
// fills the view. Neither the Hessian's eigenvalue ratio (3-9e-3 on those steps; right steps on
// the real kitchen from 2.4e-3) nor the spread of the correspondences' normals (smallest
// eigenvalue of sum n n^T over its trace: 0.018-0.057 on those steps, from 0.020 on the kitchen)
// separates them: at 3-4 m the normals' noise constrains ICP in every direction. The step errors
// alternate from frame to frame (3 mm, 6 cm, 5 cm, 3 mm, ...): each frame's pose against the
// keyframe is noise-driven along the plane, not a steady drift.
INSTANTIATE_TEST_SUITE_P(
    DISABLED_Fr1Room, SubsampledSequence,
    ::testing::Values(Case{"fr1_room", "room_fr1.yaml",
                           "tum_groundtruth/rgbd_dataset_freiburg1_room-groundtruth.txt", 3.0, 30.0,
                           0.6},
                      Case{"fr1_room", "room_fr1.yaml",
                           "tum_groundtruth/rgbd_dataset_freiburg1_room-groundtruth.txt", 1.5, 40.0,
                           0.4}));

}  // namespace
}  // namespace quadric_slam
