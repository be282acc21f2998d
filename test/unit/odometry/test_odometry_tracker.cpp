#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/odometry/odometry_tracker.h"
#include "synthetic_scene.h"

namespace quadric_slam {

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kFrameTime = 1.0 / 30.0;

// A smooth hand-held-like path in front of the room corner: 60 frames, 0.3 m and about 8 degrees
// of panning in total (5 mm and 0.15 degrees per frame at 30 Hz).
constexpr int kPathFrames = 60;
Eigen::Isometry3d groundTruth(int i) {
  const double s = static_cast<double>(i) / (kPathFrames - 1);
  const Eigen::Vector3d eye(-0.3 + 0.25 * s, -0.3 + 0.1 * std::sin(2 * M_PI * s),
                            1.5 + 0.05 * std::sin(M_PI * s));
  const Eigen::Vector3d target(2.0 + 0.3 * std::sin(2 * M_PI * s), 2.0 - 0.2 * s,
                               0.7 + 0.1 * std::cos(2 * M_PI * s));
  return synthetic::lookAt(eye, target);
}

OdometryTracker::Params sequenceParams() {
  OdometryTracker::Params p;
  // 320 x 240 clouds: every second point and the whole reference, as 640 x 480 with the defaults
  // (strides 4 and 2).
  p.icp.finest_stride = 2;
  p.icp.reference_stride = 1;
  return p;
}

struct SequenceRun {
  std::vector<OdometryTracker::Result> results;
  std::vector<Eigen::Isometry3d> truth;  // T_odom_camera, odom = first camera
};

// Tracks the first frames of the synthetic path (320 x 240, Kinect-like noise); blank_frame (if >=
// 0) gets an all-NaN cloud instead.
SequenceRun runSequence(const OdometryTracker::Params& params, int frames, int blank_frame = -1) {
  const synthetic::Scene scene = synthetic::roomScene();
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  OdometryTracker tracker(params);
  SequenceRun run;
  const Eigen::Isometry3d T_world_first = groundTruth(0);
  for (int i = 0; i < frames; ++i) {
    const Eigen::Isometry3d T_world_camera = groundTruth(i);
    auto cloud = synthetic::renderCloud(scene, T_world_camera, k, 2, 0.0015, 1000 + i);
    if (i == blank_frame) {
      for (auto& p : cloud->points)
        p.x = p.y = p.z = p.normal_x = std::numeric_limits<float>::quiet_NaN();
    }
    run.results.push_back(tracker.track(*cloud, k, i * kFrameTime));
    run.truth.push_back(T_world_first.inverse() * T_world_camera);
  }
  return run;
}

double translationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}

TEST(OdometryTracker, ParamsValidateNamesTheBadField) {
  EXPECT_NO_THROW(OdometryTracker::Params().validate());
  const auto rejects = [](void (*mutate)(OdometryTracker::Params&), const std::string& field) {
    OdometryTracker::Params p;
    mutate(p);
    try {
      p.validate();
      ADD_FAILURE() << "accepted a bad " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  rejects([](OdometryTracker::Params& p) { p.keyframe_translation = 0; }, "keyframe_translation");
  rejects([](OdometryTracker::Params& p) { p.keyframe_rotation = 4; }, "keyframe_rotation");
  rejects([](OdometryTracker::Params& p) { p.keyframe_min_overlap = 1.5; }, "keyframe_min_overlap");
  rejects([](OdometryTracker::Params& p) { p.lost_frames_before_new_keyframe = 0; },
          "lost_frames_before_new_keyframe");
  rejects([](OdometryTracker::Params& p) { p.icp.min_correspondences = 1; }, "min_correspondences");
  rejects([](OdometryTracker::Params& p) { p.icp.min_overlap_inlier_fraction = 1.5; },
          "min_overlap_inlier_fraction");
  rejects([](OdometryTracker::Params& p) { p.icp.max_rms_residual = 0; }, "max_rms_residual");
  rejects([](OdometryTracker::Params& p) { p.icp.gate_growth_depth = 0; }, "gate_growth_depth");
  rejects([](OdometryTracker::Params& p) { p.velocity_min_information = -1; },
          "velocity_min_information");
  OdometryTracker::Params bad;
  bad.icp.pyramid_levels = 9;
  EXPECT_THROW(OdometryTracker tracker(bad), std::invalid_argument);
}

// 60 noisy frames: the end drift stays below 5 mm and 0.3 degrees. Justification: each
// keyframe-to-frame alignment has a standard deviation of about 0.3-0.5 mm (its covariance, and
// IcpOnRoom.RecoversKnownRigidMotion); the path chains 3-5 keyframes, so the accumulated error is a
// random walk of about 1 mm; 5 mm leaves room for the correlated noise of smoothed normals while a
// wrong Jacobian, sign or keyframe composition gives centimetres.
TEST(OdometryTracker, SmoothSequenceHasSmallDrift) {
  const int frames = 60;
  const SequenceRun run = runSequence(sequenceParams(), frames);
  int keyframes = 0;
  double worst = 0;
  for (int i = 0; i < frames; ++i) {
    const OdometryTracker::Result& r = run.results[i];
    ASSERT_EQ(r.status, TrackingStatus::kOk) << "frame " << i << ": " << r.icp.message;
    keyframes += r.new_keyframe ? 1 : 0;
    worst = std::max(worst, translationError(r.T_odom_camera, run.truth[i]));
  }
  EXPECT_TRUE(run.results[0].new_keyframe);
  EXPECT_TRUE(run.results[0].T_odom_camera.isApprox(Eigen::Isometry3d::Identity()));
  // The path is 0.3 m long: with 10 cm keyframe spacing at least three keyframes.
  EXPECT_GE(keyframes, 3);
  EXPECT_LT(keyframes, 20);
  const OdometryTracker::Result& last = run.results.back();
  EXPECT_LT(translationError(last.T_odom_camera, run.truth.back()), 5e-3);
  EXPECT_LT(pose_math::rotationAngle(last.T_odom_camera.inverse() * run.truth.back()), 0.3 * kDeg);
  EXPECT_LT(worst, 5e-3);
  // Sanity of the path itself (the truth moved, so the estimate did too).
  EXPECT_GT(run.truth.back().translation().norm(), 0.2);
  // The covariance grows along the path and stays symmetric positive semi-definite.
  EXPECT_TRUE(last.covariance.isApprox(last.covariance.transpose(), 1e-9));
  EXPECT_GT(last.covariance.trace(), run.results[1].covariance.trace());
  EXPECT_GT(last.covariance(0, 0), 0);
  EXPECT_LT(std::sqrt(last.covariance(0, 0)), 0.01);
}

// velocity_min_information gates which ok steps set the constant-velocity prior: with the bar off
// (0) each frame's prediction is the last pose moved on by the last step (1.5 cm); with a bar no
// step reaches it is the last pose itself (velocity_hold_time 0). Both track.
TEST(OdometryTracker, OnlyStepsAboveTheInformationBarSetTheVelocity) {
  const synthetic::Scene scene = synthetic::roomScene();
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  for (const double bar : {0.0, 1000.0}) {
    OdometryTracker::Params params = sequenceParams();
    params.velocity_min_information = bar;
    OdometryTracker tracker(params);
    const Eigen::Isometry3d T_world_first = groundTruth(0);
    Eigen::Isometry3d previous = Eigen::Isometry3d::Identity();
    for (int i = 0; i < 12; ++i) {
      const Eigen::Isometry3d T_world_camera = groundTruth(3 * i);  // every third frame: 1.5 cm
      const Eigen::Isometry3d truth = T_world_first.inverse() * T_world_camera;
      auto cloud = synthetic::renderCloud(scene, T_world_camera, k, 2, 0.0015, 2000 + i);
      const OdometryTracker::Result r = tracker.track(*cloud, k, i * kFrameTime);
      ASSERT_EQ(r.status, TrackingStatus::kOk) << "bar " << bar << " frame " << i;
      EXPECT_LT(translationError(r.T_odom_camera, truth), 5e-3) << "bar " << bar << " frame " << i;
      if (i >= 2 && bar == 0.0)
        EXPECT_GT(translationError(r.T_odom_predicted, previous), 0.01) << "frame " << i;
      else if (i >= 1 && bar > 0.0)
        EXPECT_TRUE(r.T_odom_predicted.isApprox(previous, 1e-9)) << "frame " << i;
      previous = r.T_odom_camera;
    }
  }
}

// 300 noise-free frames (160 x 120, there and back along the path twice, 1.2 m): rotations stay on
// SO(3) and the drift stays below 1 cm. Guards against the composition of keyframe and prediction
// poses letting rounding errors compound: before orthonormalisation the rotation scale error grew
// about 2x per keyframe, reaching 0.3 % and 3 cm of drift after 150 frames. (What drift remains,
// about 3.5 mm, comes from normals smoothed over 10-pixel windows on these coarse clouds.)
TEST(OdometryTracker, LongRunKeepsRotationsOrthonormal) {
  const synthetic::Scene scene = synthetic::roomScene();
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  OdometryTracker::Params params;
  params.icp.finest_stride = 1;
  params.icp.reference_stride = 1;
  OdometryTracker tracker(params);
  const auto pose = [](int i) {
    // Back and forth along the 60-frame path: 0..59..0..59..0.
    const int phase = i % 120;
    return groundTruth(phase < 60 ? phase : 119 - phase);
  };
  const int frames = 300;
  double worst_orthonormality = 0;
  OdometryTracker::Result r;
  for (int i = 0; i < frames; ++i) {
    r = tracker.track(*synthetic::renderCloud(scene, pose(i), k, 4), k, i * kFrameTime);
    ASSERT_NE(r.status, TrackingStatus::kLost) << "frame " << i;
    const Eigen::Matrix3d R = r.T_odom_camera.linear();
    worst_orthonormality =
        std::max(worst_orthonormality, (R.transpose() * R - Eigen::Matrix3d::Identity()).norm());
  }
  EXPECT_LT(worst_orthonormality, 1e-9);
  const Eigen::Isometry3d truth = pose(0).inverse() * pose(frames - 1);
  EXPECT_LT(translationError(r.T_odom_camera, truth), 1e-2);
}

// More keyframes with tighter thresholds: the keyframe policy follows the motion.
TEST(OdometryTracker, KeyframeThresholdsControlKeyframes) {
  OdometryTracker::Params tight = sequenceParams();
  tight.keyframe_translation = 0.02;
  const int frames = 20;
  const SequenceRun loose_run = runSequence(sequenceParams(), frames);
  const SequenceRun tight_run = runSequence(tight, frames);
  int loose = 0, dense = 0;
  for (int i = 0; i < frames; ++i) {
    loose += loose_run.results[i].new_keyframe ? 1 : 0;
    dense += tight_run.results[i].new_keyframe ? 1 : 0;
  }
  // The first 20 frames move about 0.1 m: the loose policy takes 1-3 keyframes, 2 cm spacing 4+.
  EXPECT_LE(loose, 3);
  EXPECT_GE(dense, 4);
  EXPECT_LT(translationError(tight_run.results.back().T_odom_camera, tight_run.truth.back()), 5e-3);
}

// A blank frame mid-sequence is reported lost, keeps the last pose, and tracking resumes.
TEST(OdometryTracker, BlankFrameIsLostAndTrackingResumes) {
  const int frames = 30, blank = 15;
  const SequenceRun run = runSequence(sequenceParams(), frames, blank);
  const OdometryTracker::Result& lost = run.results[blank];
  EXPECT_EQ(lost.status, TrackingStatus::kLost);
  EXPECT_EQ(lost.consecutive_lost, 1);
  EXPECT_FALSE(lost.new_keyframe);
  EXPECT_TRUE(lost.T_odom_camera.isApprox(run.results[blank - 1].T_odom_camera));
  EXPECT_GT(lost.covariance.trace(), run.results[blank - 1].covariance.trace());
  for (int i = blank + 1; i < frames; ++i) {
    EXPECT_EQ(run.results[i].status, TrackingStatus::kOk) << "frame " << i;
    EXPECT_EQ(run.results[i].consecutive_lost, 0);
  }
  EXPECT_LT(translationError(run.results.back().T_odom_camera, run.truth.back()), 5e-3);
}

TEST(OdometryTracker, EmptyFirstFramesAreLostThenTrackingStarts) {
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  OdometryTracker tracker(sequenceParams());
  auto empty = pcl::make_shared<pcl::PointCloud<pcl::PointNormal>>(320, 240);
  for (auto& p : empty->points)
    p.x = p.y = p.z = p.normal_x = std::numeric_limits<float>::quiet_NaN();
  OdometryTracker::Result r = tracker.track(*empty, k, 0.0);
  EXPECT_EQ(r.status, TrackingStatus::kLost);
  EXPECT_FALSE(tracker.initialized());
  r = tracker.track(*empty, k, 0.1);
  EXPECT_EQ(r.consecutive_lost, 2);
  auto cloud = synthetic::renderCloud(synthetic::roomScene(), groundTruth(0), k, 2);
  r = tracker.track(*cloud, k, 0.2);
  EXPECT_EQ(r.status, TrackingStatus::kOk);
  EXPECT_TRUE(r.new_keyframe);
  EXPECT_TRUE(tracker.initialized());
  // A cloud whose size fits no decimation of the intrinsics is refused.
  auto odd = pcl::make_shared<pcl::PointCloud<pcl::PointNormal>>(300, 240);
  EXPECT_THROW(tracker.track(*odd, k, 0.3), std::invalid_argument);
}

// reset() forgets the odom frame: the next frame is the new origin.
TEST(OdometryTracker, ResetStartsNewOdomFrame) {
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  const synthetic::Scene scene = synthetic::roomScene();
  OdometryTracker tracker(sequenceParams());
  for (int i = 0; i < 5; ++i)
    tracker.track(*synthetic::renderCloud(scene, groundTruth(i * 3), k, 2), k, i * kFrameTime);
  EXPECT_FALSE(tracker.pose().isApprox(Eigen::Isometry3d::Identity()));
  tracker.reset();
  EXPECT_FALSE(tracker.initialized());
  const OdometryTracker::Result r =
      tracker.track(*synthetic::renderCloud(scene, groundTruth(30), k, 2), k, 0.0);
  EXPECT_EQ(r.status, TrackingStatus::kOk);
  EXPECT_TRUE(r.new_keyframe);
  EXPECT_TRUE(r.T_odom_camera.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(r.covariance.isZero());
}

// Facing a single wall and sliding along it: degenerate, and the pose does not run away; the
// distance to the wall (the constrained direction) is still tracked.
TEST(OdometryTracker, SingleWallIsDegenerateAndBounded) {
  synthetic::Scene wall;
  wall.planes.push_back({Eigen::Vector3d(0, 1, 0), 2.0});  // y = 2
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  OdometryTracker tracker(sequenceParams());
  const int frames = 20;
  const auto pose = [](int i) {
    // Slides 1 cm per frame along x and approaches the wall by 2 mm per frame.
    return synthetic::lookAt(Eigen::Vector3d(0.01 * i, 0.002 * i, 1.0),
                             Eigen::Vector3d(0.01 * i, 2.0, 1.0));
  };
  OdometryTracker::Result r;
  for (int i = 0; i < frames; ++i) {
    r = tracker.track(*synthetic::renderCloud(wall, pose(i), k, 2, 0.0015, 500 + i), k,
                      i * kFrameTime);
    if (i > 0) {
      EXPECT_EQ(r.status, TrackingStatus::kDegenerate) << "frame " << i;
      EXPECT_EQ(r.icp.constrained_dof, 3);
    }
    // Bounded: never further than the true motion allows in any direction.
    EXPECT_LT(r.T_odom_camera.translation().norm(), 0.01 * i + 0.05);
    EXPECT_LT(pose_math::rotationAngle(r.T_odom_camera), 2 * kDeg);
  }
  const Eigen::Isometry3d truth = pose(0).inverse() * pose(frames - 1);
  // Camera z points at the wall: the approach is observed.
  EXPECT_NEAR(r.T_odom_camera.translation().z(), truth.translation().z(), 3e-3);
  // The covariance reports the unobserved sideways direction as unknown.
  EXPECT_GT(r.covariance(0, 0), 0.5);
  EXPECT_LT(r.covariance(2, 2), 1e-3);
}

}  // namespace
}  // namespace quadric_slam

namespace quadric_slam {
namespace {

// The room scene's surfaces as quadric observations in a camera's frame (what the segmenter would
// report: every wall, the boxes' faces, the sphere).
std::vector<QuadricMeasurement> roomObservations(const Eigen::Isometry3d& T_world_camera) {
  const synthetic::Scene scene = synthetic::roomScene();
  std::vector<QuadricModel> world;
  const auto addBoxFaces = [&](const synthetic::Box& box, bool with_bottom) {
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector3d n = Eigen::Vector3d::Unit(axis);
      world.push_back(quadricFromShape(PlaneShape{n, box.max(axis)}));
      if (axis < 2 || with_bottom)
        world.push_back(quadricFromShape(PlaneShape{n, box.min(axis)}));
    }
  };
  addBoxFaces(scene.room, true);
  for (const synthetic::Box& box : scene.boxes)
    addBoxFaces(box, false);
  for (const synthetic::Sphere& sphere : scene.spheres)
    world.push_back(quadricFromShape(SphereShape{sphere.centre, sphere.radius}));
  std::vector<QuadricMeasurement> out;
  for (const QuadricModel& q : world) {
    QuadricMeasurement m;
    m.quadric_camera =
        QuadricModel(q.quadricClass(), T_world_camera.inverse() * q.pose(), q.scale());
    m.num_points = 3000;
    out.push_back(m);
  }
  return out;
}

// Frames far apart and a jerky hand (a bag played at 1-2 Hz, or a pipeline dropping frames):
// steps alternate between about 4 and 40 cm, so the constant-velocity prior is off by up to 40 cm
// and 8 degrees, beyond the basin of ICP on this scene. The surfaces' motion guess brings every
// step back.
TEST(OdometryTracker, LargeStepsAreTrackedWithTheQuadricMotionGuess) {
  const synthetic::Scene scene = synthetic::roomScene();
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  const auto pose = [](int i) {
    const double progress[] = {0.0, 0.1, 1.2, 1.3, 2.4, 2.5};  // along the path, irregular
    const double s = progress[i];
    const Eigen::Vector3d eye(-0.3 + 0.3 * s, -0.3 + 0.15 * s, 1.5);
    const Eigen::Vector3d target(2.0 - 0.4 * s, 2.0 + 0.1 * s, 0.8);
    return synthetic::lookAt(eye, target);
  };
  const auto run = [&](bool with_observations) {
    OdometryTracker tracker(sequenceParams());
    double worst = 0;
    for (int i = 0; i < 6; ++i) {
      const auto cloud = synthetic::renderCloud(scene, pose(i), k, 2, 0.0015, 2000 + i);
      const std::vector<QuadricMeasurement> observations = roomObservations(pose(i));
      const OdometryTracker::Result r =
          tracker.track(*cloud, k, i * 0.5, with_observations ? &observations : nullptr);
      const Eigen::Isometry3d truth = pose(0).inverse() * pose(i);
      worst = std::max(worst, (r.T_odom_camera.translation() - truth.translation()).norm());
    }
    return worst;
  };
  const Eigen::Isometry3d step = pose(1).inverse() * pose(2);
  ASSERT_GT(step.translation().norm(), 0.35);
  ASSERT_GT(pose_math::rotationAngle(step), 6 * kDeg);
  EXPECT_LT(run(true), 0.01);
  // Without the guess the same steps go wrong (the scene is not trivially in ICP's basin).
  EXPECT_GT(run(false), 0.03);
}

}  // namespace
}  // namespace quadric_slam
