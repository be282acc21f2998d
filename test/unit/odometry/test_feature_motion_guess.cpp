// The corners' motion guess (odometry/feature_motion_guess.h) on real Kinect frames: the shipped
// fr1_xyz pair against motion capture, and one of its frames seen from cameras moved by 15-35 cm
// and 10-30 degrees (its depth re-projected with the occlusions and holes that makes,
// sim/depth_warp.h, and its colour looked up where each new pixel's surface point was seen), the
// steps a hand-held camera makes between frames read at 1-3 Hz. Then the tracker on such a step,
// with and without the guess.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "axis_angle_motion.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/odometry/feature_motion_guess.h"
#include "quadric_slam/odometry/odometry_tracker.h"
#include "quadric_slam/odometry/pose_math.h"
#include "quadric_slam/sim/depth_warp.h"
#include "tum_fr1_xyz_pair.h"

namespace quadric_slam {
namespace {

struct ColourDepthFrame {
  cv::Mat depth_m;  // CV_32FC1, NaN: none
  cv::Mat rgb;      // CV_8UC3
};

ColourDepthFrame shippedFrame(const char* depth, const char* rgb) {
  return {readTumDepthPng(test::shippedData(depth).string()),
          readRgbPng(test::shippedData(rgb).string())};
}

// The frame seen from a camera at T_reference_moved: depth re-projected (sim/depth_warp.h), each
// new pixel's colour read (bilinearly) where the reference camera saw its surface point.
ColourDepthFrame movedView(const ColourDepthFrame& reference, const CameraIntrinsics& k,
                           const Eigen::Isometry3d& T_reference_moved) {
  ColourDepthFrame moved;
  moved.depth_m = warpDepthImage(reference.depth_m, k, T_reference_moved);
  cv::Mat map_x(k.height, k.width, CV_32FC1, cv::Scalar(-1)), map_y = map_x.clone();
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u) {
      const float z = moved.depth_m.at<float>(v, u);
      if (!(z > 0))
        continue;
      const Eigen::Vector3d p =
          T_reference_moved * Eigen::Vector3d((u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z);
      map_x.at<float>(v, u) = static_cast<float>(k.fx * p.x() / p.z() + k.cx);
      map_y.at<float>(v, u) = static_cast<float>(k.fy * p.y() / p.z() + k.cy);
    }
  cv::remap(reference.rgb, moved.rgb, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return moved;
}

cv::Mat zeroForNaN(const cv::Mat& depth_m) {
  cv::Mat out = depth_m.clone();
  cv::patchNaNs(out, 0.0);
  return out;
}

using test::motion;

double translationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.inverse() * b).translation().norm();
}
double rotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return pose_math::rotationAngle(a.inverse() * b) * 180.0 / M_PI;
}

TEST(FeatureMotionGuess, TheRealPairAgreesWithMotionCapture) {
  const CameraIntrinsics k = test::fr1Intrinsics();
  const ColourDepthFrame a = shippedFrame(test::kFr1XyzDepthA, test::kFr1XyzRgbA);
  const ColourDepthFrame b = shippedFrame(test::kFr1XyzDepthB, test::kFr1XyzRgbB);
  Eigen::Isometry3d truth;
  ASSERT_TRUE(test::fr1XyzTrueMotion(test::kFr1XyzRgbStampA, test::kFr1XyzRgbStampB, &truth));
  FeatureMotionGuesser guesser;
  const FeatureFrame fa = guesser.describe(a.rgb, zeroForNaN(a.depth_m), k);
  const FeatureFrame fb = guesser.describe(b.rgb, zeroForNaN(b.depth_m), k);
  ASSERT_GT(fa.points.size(), 500u);
  const FeatureMotionGuess g = guesser.guess(fa, fb);
  ASSERT_TRUE(g.found) << g.message;
  EXPECT_GT(g.inliers, 100);
  // Motion capture against a 2.6 cm, 2 degree step: within 2 cm and a degree (the colour is taken
  // 12-15 ms after the depth by a moving camera; the corners' depths carry the sensor's noise).
  EXPECT_LT(translationError(g.T_reference_current, truth), 0.02);
  EXPECT_LT(rotationErrorDeg(g.T_reference_current, truth), 1.0);
  EXPECT_EQ(guesser.agreeingMatches(g, g.T_reference_current), g.inliers);
  // A pose 20 cm off agrees with few of the corners.
  const Eigen::Isometry3d off = motion({0.2, 0, 0}, {0, 1, 0}, 0) * g.T_reference_current;
  EXPECT_LT(guesser.agreeingMatches(g, off), g.inliers / 4);
}

class LargeWarpedSteps : public ::testing::TestWithParam<Eigen::Isometry3d> {};

TEST_P(LargeWarpedSteps, TheGuessRecoversTheMotion) {
  const CameraIntrinsics k = test::fr1Intrinsics();
  const ColourDepthFrame a = shippedFrame(test::kFr1XyzDepthA, test::kFr1XyzRgbA);
  const Eigen::Isometry3d truth = GetParam();
  const ColourDepthFrame b = movedView(a, k, truth);
  FeatureMotionGuesser guesser;
  const FeatureMotionGuess g = guesser.guess(guesser.describe(a.rgb, zeroForNaN(a.depth_m), k),
                                             guesser.describe(b.rgb, zeroForNaN(b.depth_m), k));
  ASSERT_TRUE(g.found) << g.message;
  EXPECT_LT(translationError(g.T_reference_current, truth), 0.02)
      << g.inliers << " of " << g.matches;
  EXPECT_LT(rotationErrorDeg(g.T_reference_current, truth), 1.0);
}

INSTANTIATE_TEST_SUITE_P(FeatureMotionGuess, LargeWarpedSteps,
                         ::testing::Values(motion({0.15, 0.0, 0.05}, {0, 1, 0}, 10),
                                           motion({-0.25, 0.05, 0.1}, {0.2, 1, 0.1}, -15),
                                           motion({0.1, -0.1, -0.2}, {1, 0.3, 0}, 20),
                                           motion({0.2, 0.0, 0.25}, {0, 1, 0.2}, 30)));

TEST(FeatureMotionGuess, ImagesWithoutSharedCornersGiveNoGuess) {
  const CameraIntrinsics k = test::fr1Intrinsics();
  const ColourDepthFrame a = shippedFrame(test::kFr1XyzDepthA, test::kFr1XyzRgbA);
  FeatureMotionGuesser guesser;
  const FeatureFrame fa = guesser.describe(a.rgb, zeroForNaN(a.depth_m), k);
  // A blank image has no corners.
  const cv::Mat blank(k.height, k.width, CV_8UC3, cv::Scalar(128, 128, 128));
  const FeatureMotionGuess none =
      guesser.guess(fa, guesser.describe(blank, zeroForNaN(a.depth_m), k));
  EXPECT_FALSE(none.found);
  EXPECT_FALSE(none.message.empty());
  // The image upside down over the same depth: corners that match by chance agree on no motion.
  cv::Mat flipped;
  cv::flip(a.rgb, flipped, 0);
  const FeatureMotionGuess unrelated =
      guesser.guess(fa, guesser.describe(flipped, zeroForNaN(a.depth_m), k));
  EXPECT_FALSE(unrelated.found) << unrelated.inliers << " of " << unrelated.matches;
  // Corners without depth are not used at all.
  const cv::Mat no_depth(k.height, k.width, CV_32FC1, cv::Scalar(0));
  EXPECT_TRUE(guesser.describe(a.rgb, no_depth, k).empty());
}

TEST(FeatureMotionGuess, DepthOnAnOrganizedCloudsGridLiftsTheSameCorners) {
  const CameraIntrinsics k = test::fr1Intrinsics();
  const ColourDepthFrame a = shippedFrame(test::kFr1XyzDepthA, test::kFr1XyzRgbA);
  cv::Mat half;
  cv::resize(zeroForNaN(a.depth_m), half, cv::Size(k.width / 2, k.height / 2), 0, 0,
             cv::INTER_NEAREST);
  FeatureMotionGuesser guesser;
  const FeatureFrame full = guesser.describe(a.rgb, zeroForNaN(a.depth_m), k);
  const FeatureFrame decimated = guesser.describe(a.rgb, half, k);
  // Nearly the same corners lifted (a grid cell's depth for its four pixels), and the guess
  // between the two is the identity.
  EXPECT_NEAR(static_cast<double>(decimated.points.size()), full.points.size(),
              0.1 * full.points.size());
  const FeatureMotionGuess g = guesser.guess(full, decimated);
  ASSERT_TRUE(g.found) << g.message;
  EXPECT_LT(g.T_reference_current.translation().norm(), 0.01);
  EXPECT_THROW(guesser.describe(a.rgb, cv::Mat(100, 100, CV_32FC1, cv::Scalar(1)), k),
               std::invalid_argument);
  EXPECT_THROW(guesser.describe(cv::Mat(10, 10, CV_8UC3), zeroForNaN(a.depth_m), k),
               std::invalid_argument);
}

TEST(FeatureMotionGuess, BadParamsAreNamed) {
  FeatureMotionGuesser::Params p;
  p.match_ratio = 1.5;
  try {
    p.validate();
    ADD_FAILURE() << "match_ratio 1.5 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("match_ratio"), std::string::npos) << e.what();
  }
  p = FeatureMotionGuesser::Params();
  p.max_depth = p.min_depth;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = FeatureMotionGuesser::Params();
  p.min_inliers = 2;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = FeatureMotionGuesser::Params();
  p.inlier_pixels = 0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

// The tracker on a real frame and its view from 25 cm and 20 degrees away, 0.67 s later (a
// camera read at 1.5 Hz): beyond ICP's basin from the still prior. With the corners' guess the
// step is found; without it the tracker must not claim it.
TEST(FeatureMotionGuess, TheTrackerFollowsALargeStepFromTheCorners) {
  const CameraIntrinsics k = test::fr1Intrinsics();
  const ColourDepthFrame a = shippedFrame(test::kFr1XyzDepthA, test::kFr1XyzRgbA);
  const Eigen::Isometry3d truth = motion({0.2, 0.0, 0.25}, {0, 1, 0.2}, 30);
  const ColourDepthFrame b = movedView(a, k, truth);
  const NormalEstimator normals{NormalEstimator::Params()};
  const auto cloudOf = [&](const ColourDepthFrame& f) {
    return normals.compute(backProject(depthViewOf(f.depth_m), k, BackProjectionParams()));
  };
  const OdometryTracker::Cloud cloud_a = cloudOf(a), cloud_b = cloudOf(b);
  for (const bool corners : {true, false}) {
    OdometryTracker::Params params;
    params.feature_motion_guess = corners;
    params.photometric_refinement = true;
    OdometryTracker tracker(params);
    tracker.track(cloud_a, k, 0.0, nullptr, &a.rgb);
    const OdometryTracker::Result r = tracker.track(cloud_b, k, 0.67, nullptr, &b.rgb);
    const double t_err = translationError(r.T_odom_camera, truth);
    const double r_err = rotationErrorDeg(r.T_odom_camera, truth);
    if (corners) {
      EXPECT_TRUE(r.feature_guess.found) << r.feature_guess.message;
      EXPECT_TRUE(r.started_from_features);
      EXPECT_NE(r.status, TrackingStatus::kLost);
      EXPECT_LT(t_err, 0.02);
      EXPECT_LT(r_err, 1.0);
    } else {
      EXPECT_FALSE(r.feature_guess.found);
      // Without the corners the step is out of reach; the tracker may not say ok on it.
      if (r.status == TrackingStatus::kOk) {
        EXPECT_LT(t_err, 0.05);
      }
      EXPECT_GT(t_err, 0.05) << "the step was in ICP's basin: the test would not show the guess";
    }
  }
}

// A camera that turns 30 degrees one way and then 55 degrees back, 0.67 s apart: the third view
// shares little with the second (the keyframe) but much with the first. With the earlier
// keyframes' corners kept it is placed from the first; without them the tracker must not claim it.
TEST(FeatureMotionGuess, AnEarlierKeyframesCornersPlaceASwingBack) {
  const CameraIntrinsics k = test::fr1Intrinsics();
  const ColourDepthFrame a = shippedFrame(test::kFr1XyzDepthA, test::kFr1XyzRgbA);
  const Eigen::Isometry3d T_a_b = motion({0.25, 0.0, 0.05}, {0, 1, 0}, 30);
  const Eigen::Isometry3d T_a_c = motion({-0.2, 0.02, 0.0}, {0, 1, 0}, -25);
  const ColourDepthFrame b = movedView(a, k, T_a_b), c = movedView(a, k, T_a_c);
  const NormalEstimator normals{NormalEstimator::Params()};
  const auto cloudOf = [&](const ColourDepthFrame& f) {
    return normals.compute(backProject(depthViewOf(f.depth_m), k, BackProjectionParams()));
  };
  const OdometryTracker::Cloud cloud_a = cloudOf(a), cloud_b = cloudOf(b), cloud_c = cloudOf(c);
  for (const int history : {10, 0}) {
    OdometryTracker::Params params;
    params.feature_motion_guess = true;
    params.feature_history_keyframes = history;
    params.photometric_refinement = true;
    OdometryTracker tracker(params);
    tracker.track(cloud_a, k, 0.0, nullptr, &a.rgb);
    const OdometryTracker::Result rb = tracker.track(cloud_b, k, 0.67, nullptr, &b.rgb);
    ASSERT_TRUE(rb.new_keyframe);
    ASSERT_LT(translationError(rb.T_odom_camera, T_a_b), 0.02);
    const OdometryTracker::Result rc = tracker.track(cloud_c, k, 1.33, nullptr, &c.rgb);
    const double t_err = translationError(rc.T_odom_camera, T_a_c);
    if (history > 0) {
      EXPECT_EQ(rc.feature_keyframes_back, 1) << rc.feature_guess.message;
      EXPECT_NE(rc.status, TrackingStatus::kLost) << rc.icp.message;
      EXPECT_LT(t_err, 0.02);
      EXPECT_LT(rotationErrorDeg(rc.T_odom_camera, T_a_c), 1.0);
    } else {
      EXPECT_EQ(rc.feature_keyframes_back, 0);
      if (rc.status == TrackingStatus::kOk) {
        EXPECT_LT(t_err, 0.05);
      }
      EXPECT_GT(t_err, 0.05) << "the keyframe's corners reached the swing back: the test would "
                                "not show the earlier keyframes'";
    }
  }
}

// The camera turns 15 and then 30 degrees one way and comes back to 15 degrees the other side of
// where it started, 0.67 s apart: the last view shares little with the keyframe (45 degrees), some
// with the keyframe before (30 degrees) and most with the first (15). The earlier keyframe whose
// corners agree the most places it, not the newest that gives a guess.
TEST(FeatureMotionGuess, TheEarlierKeyframeSharingTheMostPlacesTheFrame) {
  const CameraIntrinsics k = test::fr1Intrinsics();
  const ColourDepthFrame first = shippedFrame(test::kFr1XyzDepthA, test::kFr1XyzRgbA);
  const std::vector<Eigen::Isometry3d> path = {
      Eigen::Isometry3d::Identity(), motion({0.12, 0.0, 0.02}, {0, 1, 0}, 15),
      motion({0.22, 0.0, 0.05}, {0, 1, 0}, 30), motion({-0.12, 0.01, 0.0}, {0, 1, 0}, -15)};
  std::vector<ColourDepthFrame> views = {first};
  for (size_t i = 1; i < path.size(); ++i)
    views.push_back(movedView(first, k, path[i]));
  // The newest earlier keyframe does give a guess, with fewer agreeing corners than the first.
  FeatureMotionGuesser guesser;
  const auto describe = [&](const ColourDepthFrame& f) {
    return guesser.describe(f.rgb, zeroForNaN(f.depth_m), k);
  };
  const FeatureFrame last = describe(views[3]);
  const FeatureMotionGuess from_newest = guesser.guess(describe(views[1]), last);
  const FeatureMotionGuess from_first = guesser.guess(describe(views[0]), last);
  ASSERT_TRUE(from_newest.found) << "the test would not tell the newest from the strongest";
  ASSERT_TRUE(from_first.found);
  ASSERT_LT(from_newest.inliers, from_first.inliers);

  const NormalEstimator normals{NormalEstimator::Params()};
  OdometryTracker::Params params;
  params.feature_motion_guess = true;
  params.feature_history_keyframes = 10;
  params.photometric_refinement = true;
  OdometryTracker tracker(params);
  OdometryTracker::Result r;
  for (size_t i = 0; i < path.size(); ++i) {
    const OdometryTracker::Cloud cloud =
        normals.compute(backProject(depthViewOf(views[i].depth_m), k, BackProjectionParams()));
    r = tracker.track(cloud, k, 0.67 * static_cast<double>(i), nullptr, &views[i].rgb);
    if (i < 3) {
      ASSERT_TRUE(r.new_keyframe) << "frame " << i;
      ASSERT_LT(translationError(r.T_odom_camera, path[i]), 0.02) << "frame " << i;
    }
  }
  EXPECT_EQ(r.feature_keyframes_back, 2) << r.feature_guess.message;
  EXPECT_NE(r.status, TrackingStatus::kLost) << r.icp.message;
  EXPECT_LT(translationError(r.T_odom_camera, path[3]), 0.02);
  EXPECT_LT(rotationErrorDeg(r.T_odom_camera, path[3]), 1.0);
}

}  // namespace
}  // namespace quadric_slam
