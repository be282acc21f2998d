// Honest tracking status on sub-sampled sequences: scenes rendered with the harsh Kinect v1 model
// along the real fr1_desk (the desk scene) and fr1_room (a room around its path) hand-held
// trajectories, sampled at 3 Hz and 1.5 Hz
// (every 10th and every 20th frame of the 30 Hz recording: steps of up to 25 cm and 20 degrees).
// The tracker may say lost, but never ok on a step off by more than 5 cm or 5 degrees (issue 12);
// at full rate (30 Hz, steps of 1-2 cm) never by more than 2 cm.
#include <gtest/gtest.h>

#include <iostream>
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
  double min_ok_share;              // the tracker must still track this share of the frames
  double max_ok_step_error = 0.05;  // m: ok never comes with a larger step error
};

test::TrackingRun runCase(const Case& c, Trajectory* truth) {
  const Scene scene =
      readSceneYaml(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/" + c.scene);
  SyntheticFrameSource::Params source_params;
  source_params.driving_trajectory = test::sharedData(c.trajectory).string();
  source_params.rate = c.rate;
  source_params.seconds = c.seconds;
  source_params.seed = 3;
  // Colour at the sub-sampled rates, where the corners' guess and the intensities run; at full
  // rate depth alone (the far-wall honesty case).
  source_params.rgb = c.rate < 10.0;
  SyntheticFrameSource source(scene, source_params);
  *truth = source.groundTruth();
  return test::runTracker(
      source, *truth, loadSlamParams(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config"), 1, 2000);
}

class SubsampledSequence : public ::testing::TestWithParam<Case> {};

TEST_P(SubsampledSequence, OkNeverComesWithAWrongStep) {
  const Case c = GetParam();
  QS_SKIP_WITHOUT_SHARED_DATA(test::sharedData(c.trajectory), test::kFullGroundTruth);
  Trajectory truth;
  const test::TrackingRun run = runCase(c, &truth);
  const std::string name = std::string(c.name) + "_" + std::to_string(int(c.rate * 10)) + "dhz";
  test::writeTrackingCsv(run, name);
  std::cout << name << ": " << run.frames.size() << " frames, ok " << run.ok << " degenerate "
            << run.degenerate << " lost " << run.lost << "; worst ok step error "
            << run.worstOkTranslation() << " m, " << run.worstOkRotationDeg()
            << " deg; odometry ATE " << test::ateRmse(run, truth) << " m\n";
  ASSERT_GE(run.frames.size(), 20u);
  EXPECT_LE(run.worstOkTranslation(), c.max_ok_step_error);
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

// The room around the fr1_room path (room_fr1.yaml): where a far wall (3-4.5 m) or the floor fills
// the view, the normals' noise (15-25 degrees there) used to pass for information along the plane:
// the tracker said ok on 12 of 90 steps off by 5-47 cm at 3 Hz, 7 of 60 at 1.5 Hz (up to 29 cm),
// and at full rate on 80 of the first 600 steps off by 2-16 cm (true steps 1-2 cm). Judged against
// that noise (noise_information_factor) such views are degenerate: fewer frames are ok (measured
// 0.36, 0.32 and 0.42 of them), none on a wrong step (worst 2.0 cm, 2.4 cm and 0.7 cm; with the
// segmented surfaces' normals and min_eigenvalue_ratio 1.2e-3, 2026-12-04: ok 0.60, 0.48, 0.71,
// worst 3.1 cm, 3.7 cm and 1.9 cm, the last in the stretch where a wall and a box fill the view).
// The full-rate case takes the first 20 s (the far-wall stretch at 8.6-14.3 s had the errors up to
// 16 cm): the whole 49 s take three minutes.
INSTANTIATE_TEST_SUITE_P(
    Fr1Room, SubsampledSequence,
    ::testing::Values(Case{"fr1_room", "room_fr1.yaml",
                           "tum_groundtruth/rgbd_dataset_freiburg1_room-groundtruth.txt", 3.0, 30.0,
                           0.3},
                      Case{"fr1_room", "room_fr1.yaml",
                           "tum_groundtruth/rgbd_dataset_freiburg1_room-groundtruth.txt", 1.5, 40.0,
                           0.25},
                      Case{"fr1_room", "room_fr1.yaml",
                           "tum_groundtruth/rgbd_dataset_freiburg1_room-groundtruth.txt", 30.0,
                           20.0, 0.35, 0.02}));

}  // namespace
}  // namespace quadric_slam
