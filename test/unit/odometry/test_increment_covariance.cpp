// The tracker's frame-to-frame increment covariance
// (OdometryTracker::Result::increment_covariance): against a Monte Carlo of a synthetic ICP problem
// (the derivation in OdometryTracker::track), its composition from ICP's covariance, the
// calibration keys, and the lost / first / degenerate cases.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/odometry/odometry_tracker.h"
#include "synthetic_scene.h"

namespace quadric_slam {
namespace {

constexpr double kFrameTime = 1.0 / 30.0;
constexpr double kDepthNoise = 0.0015;  // m: the synthetic sensor's Gaussian depth noise

// 320 x 240 clouds as in the tracker's other tests; no motion guess (no observations are given).
// ICP's covariance as it is (no calibration): the synthetic depth noise is independent per pixel,
// which is what sigma^2 H^-1 assumes.
OdometryTracker::Params params() {
  OdometryTracker::Params p;
  p.icp.finest_stride = 2;
  p.icp.reference_stride = 1;
  p.increment_covariance_scale = 1.0;
  p.increment_translation_fraction = 0.0;
  p.increment_rotation_per_metre = 0.0;
  return p;
}

// Three views of the room: the keyframe and two frames about 6 and 12 mm and a fraction of a degree
// further on, so that both are tracked against the same keyframe.
Eigen::Isometry3d view(int i) {
  return synthetic::lookAt(Eigen::Vector3d(-0.3 + 0.006 * i, -0.3 + 0.002 * i, 1.5),
                           Eigen::Vector3d(2.0, 2.0 - 0.01 * i, 0.7));
}

// The body-tangent error xi of an estimated step against the true one: T_true = T_est exp(xi^).
Vector6d stepError(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  return logSE3(estimate.inverse() * truth);
}

// Monte Carlo: the keyframe is noise-free (ICP's sigma^2 H^-1 describes the current cloud's noise;
// a noisy keyframe would add one bias shared by every trial), the two frames get fresh depth noise
// in every trial. The sample covariance of the increment's error must match the reported one:
// per-direction variance within a factor 2 and a mean NEES near 6. Dropping the previous frame's
// term (Ad C_p Ad^T) halves the covariance and doubles the NEES (7.4 here, so about 15); with C_p
// added unmapped or the increment taken as the cumulative difference the directions disagree.
TEST(IncrementCovariance, MatchesMonteCarloOfTwoFramesOnOneKeyframe) {
  const synthetic::Scene scene = synthetic::roomScene();
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  const auto keyframe = synthetic::renderCloud(scene, view(0), k, 2, 0.0, 1);
  const Eigen::Isometry3d true_increment = view(1).inverse() * view(2);
  const int trials = 40;
  std::vector<Vector6d> errors;
  Matrix6d mean_reported = Matrix6d::Zero();
  for (int t = 0; t < trials; ++t) {
    OdometryTracker tracker(params());
    tracker.track(*keyframe, k, 0.0);
    const OdometryTracker::Result p = tracker.track(
        *synthetic::renderCloud(scene, view(1), k, 2, kDepthNoise, 100 + t), k, kFrameTime);
    const OdometryTracker::Result c = tracker.track(
        *synthetic::renderCloud(scene, view(2), k, 2, kDepthNoise, 500 + t), k, 2 * kFrameTime);
    ASSERT_EQ(p.status, TrackingStatus::kOk) << p.icp.message;
    ASSERT_EQ(c.status, TrackingStatus::kOk) << c.icp.message;
    ASSERT_FALSE(p.new_keyframe);  // both against the first keyframe
    EXPECT_TRUE(c.increment.isApprox(p.T_odom_camera.inverse() * c.T_odom_camera, 1e-9));
    errors.push_back(stepError(c.increment, true_increment));
    mean_reported += c.increment_covariance / trials;
  }
  Vector6d mean = Vector6d::Zero();
  for (const Vector6d& e : errors)
    mean += e / trials;
  Matrix6d sample = Matrix6d::Zero();
  for (const Vector6d& e : errors)
    sample += (e - mean) * (e - mean).transpose() / (trials - 1);
  // The estimate is unbiased to well within its spread (a wrong sign or frame would bias it).
  for (int i = 0; i < 6; ++i)
    EXPECT_LT(std::abs(mean(i)),
              3.0 * std::sqrt(sample(i, i)) / std::sqrt(trials) + 0.5 * std::sqrt(sample(i, i)))
        << "direction " << i;
  for (int i = 0; i < 6; ++i) {
    const double ratio = sample(i, i) / mean_reported(i, i);
    RecordProperty("variance_ratio_" + std::to_string(i), std::to_string(ratio));
    EXPECT_GT(ratio, 0.5) << "direction " << i << ": sample " << sample(i, i) << " reported "
                          << mean_reported(i, i);
    EXPECT_LT(ratio, 2.0) << "direction " << i << ": sample " << sample(i, i) << " reported "
                          << mean_reported(i, i);
  }
  const Eigen::LDLT<Matrix6d> information(mean_reported);
  double nees = 0;
  for (const Vector6d& e : errors)
    nees += e.dot(information.solve(e)) / trials;
  RecordProperty("mean_nees", std::to_string(nees));
  EXPECT_GT(nees, 3.0);
  EXPECT_LT(nees, 9.5);
}

// The increment right after a keyframe is one alignment: ICP's covariance moved to the body tangent
// (Ad(T^-1) C Ad(T^-1)^T) times increment_covariance_scale, plus the step's variances
// (increment_translation_fraction and increment_rotation_per_metre times the step's length); the
// next increment adds the previous frame's term.
TEST(IncrementCovariance, ComposesIcpCovarianceWithTheCalibration) {
  const synthetic::Scene scene = synthetic::roomScene();
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  OdometryTracker::Params p = params();
  p.increment_covariance_scale = 4.0;
  p.increment_translation_fraction = 0.05;
  p.increment_rotation_per_metre = 0.2;
  OdometryTracker tracker(p);
  tracker.track(*synthetic::renderCloud(scene, view(0), k, 2, kDepthNoise, 1), k, 0.0);
  const OdometryTracker::Result a =
      tracker.track(*synthetic::renderCloud(scene, view(1), k, 2, kDepthNoise, 2), k, kFrameTime);
  const OdometryTracker::Result b = tracker.track(
      *synthetic::renderCloud(scene, view(2), k, 2, kDepthNoise, 3), k, 2 * kFrameTime);
  ASSERT_EQ(a.status, TrackingStatus::kOk);
  ASSERT_EQ(b.status, TrackingStatus::kOk);
  ASSERT_FALSE(a.new_keyframe);
  const auto relative = [&](const OdometryTracker::Result& r) {
    const Matrix6d ad = adjointSE3(r.icp.T_reference_current.inverse());
    return Matrix6d(ad * r.icp.covariance * ad.transpose());
  };
  const auto stepVariances = [](const Eigen::Isometry3d& increment) {
    const double t = 0.05 * increment.translation().norm();
    const double r = 0.2 * increment.translation().norm();
    return Matrix6d(
        (Vector6d() << t * t, t * t, t * t, r * r, r * r, r * r).finished().asDiagonal());
  };
  const Matrix6d expected_a = 4.0 * relative(a) + stepVariances(a.increment);
  EXPECT_TRUE(a.increment_covariance.isApprox(expected_a, 1e-9));
  const Matrix6d ad_back = adjointSE3(b.increment.inverse());
  const Matrix6d expected_b = 4.0 * (ad_back * relative(a) * ad_back.transpose() + relative(b)) +
                              stepVariances(b.increment);
  EXPECT_TRUE(b.increment_covariance.isApprox(expected_b, 1e-9));
  // The step of about 6 mm: its 5% (0.3 mm) is of the size of ICP's own sigma, so both count.
  EXPECT_GT(std::sqrt(a.increment_covariance(0, 0)), 0.05 * a.increment.translation().norm());
}

// No previous frame and a lost frame: the motion is unknown (degenerate_variance everywhere, the
// pose kept); the first frame after the loss is relative to the kept pose and finite again.
TEST(IncrementCovariance, FirstAndLostFramesCarryTheUnknownMotion) {
  const synthetic::Scene scene = synthetic::roomScene();
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  OdometryTracker::Params p = params();
  p.icp.degenerate_variance = 2.5;
  OdometryTracker tracker(p);
  const OdometryTracker::Result first =
      tracker.track(*synthetic::renderCloud(scene, view(0), k, 2, kDepthNoise, 1), k, 0.0);
  EXPECT_TRUE(first.increment.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(first.increment_covariance.isApprox(2.5 * Matrix6d::Identity()));
  const OdometryTracker::Result tracked =
      tracker.track(*synthetic::renderCloud(scene, view(1), k, 2, kDepthNoise, 2), k, kFrameTime);
  ASSERT_EQ(tracked.status, TrackingStatus::kOk);
  auto blank = synthetic::renderCloud(scene, view(2), k, 2, kDepthNoise, 3);
  for (auto& q : blank->points)
    q.x = q.y = q.z = q.normal_x = std::numeric_limits<float>::quiet_NaN();
  const OdometryTracker::Result lost = tracker.track(*blank, k, 2 * kFrameTime);
  ASSERT_EQ(lost.status, TrackingStatus::kLost);
  EXPECT_TRUE(lost.increment.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(lost.increment_covariance.isApprox(2.5 * Matrix6d::Identity()));
  const OdometryTracker::Result back = tracker.track(
      *synthetic::renderCloud(scene, view(3), k, 2, kDepthNoise, 4), k, 3 * kFrameTime);
  ASSERT_EQ(back.status, TrackingStatus::kOk);
  EXPECT_TRUE(back.increment.isApprox(tracked.T_odom_camera.inverse() * back.T_odom_camera, 1e-9));
  // Two alignments' worth (the kept pose's and this one's): millimetres, not the unknown motion.
  EXPECT_LT(back.increment_covariance.trace(), 1e-4);
  EXPECT_GT(back.increment_covariance.trace(), 0.0);
}

// Sliding along a single wall: the step along the wall is unknown, the approach is measured. In the
// body frame (camera z at the wall, x along it) the increment covariance says so.
TEST(IncrementCovariance, DegenerateStepIsLargeAlongTheWeakDirectionsOnly) {
  synthetic::Scene wall;
  wall.planes.push_back({Eigen::Vector3d(0, 1, 0), 2.0});  // y = 2
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  OdometryTracker tracker(params());
  const auto pose = [](int i) {
    return synthetic::lookAt(Eigen::Vector3d(0.01 * i, 0.002 * i, 1.0),
                             Eigen::Vector3d(0.01 * i, 2.0, 1.0));
  };
  OdometryTracker::Result r;
  for (int i = 0; i < 3; ++i)
    r = tracker.track(*synthetic::renderCloud(wall, pose(i), k, 2, kDepthNoise, 50 + i), k,
                      i * kFrameTime);
  ASSERT_EQ(r.status, TrackingStatus::kDegenerate);
  EXPECT_GT(r.increment_covariance(0, 0), 0.5);   // along the wall (camera x)
  EXPECT_GT(r.increment_covariance(1, 1), 0.5);   // along the wall (camera y)
  EXPECT_LT(r.increment_covariance(2, 2), 1e-4);  // towards the wall (camera z)
  EXPECT_GT(r.increment_covariance(5, 5), 0.5);   // about the wall's normal (camera z)
  EXPECT_LT(r.increment_covariance(3, 3), 1e-4);  // tilting against the wall
  EXPECT_LT(r.increment_covariance(4, 4), 1e-4);
}

TEST(IncrementCovariance, CalibrationKeysAreValidated) {
  const auto rejects = [](auto change, const std::string& field) {
    OdometryTracker::Params p;
    change(p);
    try {
      p.validate();
      ADD_FAILURE() << field << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  rejects([](OdometryTracker::Params& p) { p.increment_covariance_scale = 0; },
          "increment_covariance_scale");
  rejects([](OdometryTracker::Params& p) { p.increment_covariance_scale = 2e6; },
          "increment_covariance_scale");
  rejects([](OdometryTracker::Params& p) { p.increment_translation_fraction = -1e-3; },
          "increment_translation_fraction");
  rejects(
      [](OdometryTracker::Params& p) {
        p.increment_rotation_per_metre = std::numeric_limits<double>::infinity();
      },
      "increment_rotation_per_metre");
  OdometryTracker::Params fine;
  fine.increment_covariance_scale = 1e6;
  fine.increment_translation_fraction = 0;
  fine.increment_rotation_per_metre = 0;
  EXPECT_NO_THROW(fine.validate());
}

}  // namespace
}  // namespace quadric_slam
