// The intensities' refinement of a depth alignment along its free directions
// (odometry/photometric_refinement.h): a textured wall seen from two poses that differ along the
// wall, which depth alone cannot tell apart.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/core.hpp>

#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/odometry/odometry_tracker.h"
#include "quadric_slam/odometry/photometric_refinement.h"
#include "quadric_slam/odometry/pose_math.h"
#include "synthetic_scene.h"
#include "textured_wall.h"

namespace quadric_slam {
namespace {

using synthetic::render;
using synthetic::vgaIntrinsics;
using synthetic::View;

// A wall facing the camera leaves free the translations along it and the turn about its normal.
PhotometricRefinement::Directions alongTheWall() {
  PhotometricRefinement::Directions free = PhotometricRefinement::Directions::Zero(6, 3);
  free(0, 0) = 1;  // v_x
  free(1, 1) = 1;  // v_y
  free(5, 2) = 1;  // omega_z
  return free;
}

Eigen::Isometry3d motionAlongTheWall(double x, double y, double turn) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0);
  return T;
}

// The refinement of the current view's pose from start along the wall's free directions.
PhotometricRefinement::Result refineAlongTheWall(
    const View& reference, const View& current, const Eigen::Isometry3d& start,
    const PhotometricRefinement::Params& params = PhotometricRefinement::Params()) {
  const PhotometricRefinement refinement(params);
  return refinement.refine(IntensityPyramid::fromImage(reference.image, params.levels),
                           IntensityPyramid::fromImage(current.image, params.levels), current.cloud,
                           vgaIntrinsics(), start, alongTheWall());
}

// The refinement ended within 2 mm and 1 mrad of the truth.
void expectRecovered(const Eigen::Isometry3d& truth, const PhotometricRefinement::Result& result) {
  const Eigen::Isometry3d error = truth.inverse() * result.T_reference_current;
  EXPECT_LT(error.translation().norm(), 0.002);
  EXPECT_LT(pose_math::rotationAngle(error), 0.001);
}

TEST(PhotometricRefinement, RecoversAMotionAlongATexturedWallFromTheDepthAlignment) {
  const Eigen::Isometry3d truth = motionAlongTheWall(0.03, -0.02, 0.01);
  const View reference = render(Eigen::Isometry3d::Identity());
  const View current = render(truth);
  // The depth alignment stopped where it started along the wall (at the reference pose).
  const PhotometricRefinement::Result result =
      refineAlongTheWall(reference, current, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(result.refined) << result.message;
  expectRecovered(truth, result);
  EXPECT_LT(result.rms_after, 0.5 * result.rms_before);
  EXPECT_GE(result.points, PhotometricRefinement::Params().min_points);
  ASSERT_EQ(result.information.rows(), 3);
  EXPECT_GT(result.information.determinant(), 0);
}

TEST(PhotometricRefinement, KeepsTheConstrainedDirectionsOfTheStart) {
  const Eigen::Isometry3d truth = motionAlongTheWall(0.02, 0.015, -0.008);
  const View reference = render(Eigen::Isometry3d::Identity());
  const View current = render(truth);
  // The start is off the truth along the wall's normal by 5 mm; only the free directions move.
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  start.translation().z() = 0.005;
  const PhotometricRefinement::Result result = refineAlongTheWall(reference, current, start);
  ASSERT_TRUE(result.refined) << result.message;
  EXPECT_NEAR(result.T_reference_current.translation().z(), 0.005, 1e-9);
  const Eigen::Vector3d axis = Eigen::AngleAxisd(result.T_reference_current.linear()).axis();
  EXPECT_GT(std::abs(axis.z()), 1 - 1e-9);  // turned about the wall's normal only
  EXPECT_NEAR(result.T_reference_current.translation().x(), 0.02, 0.004);
  EXPECT_NEAR(result.T_reference_current.translation().y(), 0.015, 0.004);
}

// A real camera's auto exposure brightens a whole image between frames; the refinement estimates
// the offset with the pose instead of moving the pose to explain it.
TEST(PhotometricRefinement, ABrightnessChangeBetweenTheImagesIsTakenUpByTheOffset) {
  const Eigen::Isometry3d truth = motionAlongTheWall(0.02, -0.015, 0.008);
  const View reference = render(Eigen::Isometry3d::Identity());
  View current = render(truth);
  current.image += cv::Scalar(12);  // the texture stays below 255 - 12
  const PhotometricRefinement::Result result =
      refineAlongTheWall(reference, current, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(result.refined) << result.message;
  expectRecovered(truth, result);
  EXPECT_NEAR(result.brightness_offset, -12.0, 1.0);  // keyframe minus frame
}

// With the depth's information as a prior over all six directions, a start whose measured
// directions are off (a tilt the depth got wrong by its systematic error) is corrected by the
// intensities as far as the prior lets them: a weak prior lets the intensities decide, a strong
// one keeps the depth's answer along what it measured.
TEST(PhotometricRefinement, ADepthPriorWeighsTheMeasuredDirectionsAgainstTheIntensities) {
  const Eigen::Isometry3d truth = motionAlongTheWall(0.02, 0.01, 0.005);
  const View reference = render(Eigen::Isometry3d::Identity());
  const View current = render(truth);
  // The depth's start: right along the normal, tilted 0.5 degrees about x, nothing along the wall.
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  start.linear() = Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  // The depth measured v_z, omega_x and omega_y with a standard deviation sigma each.
  auto prior = [](double sigma_translation, double sigma_rotation) {
    Matrix6d information = Matrix6d::Zero();
    information(2, 2) = 1 / (sigma_translation * sigma_translation);
    information(3, 3) = information(4, 4) = 1 / (sigma_rotation * sigma_rotation);
    return information;
  };
  const PhotometricRefinement refinement{PhotometricRefinement::Params()};
  const IntensityPyramid reference_intensity = IntensityPyramid::fromImage(reference.image, 3);
  const IntensityPyramid current_intensity = IntensityPyramid::fromImage(current.image, 3);
  const auto all = PhotometricRefinement::Directions::Identity(6, 6);

  const PhotometricRefinement::Result weak =
      refinement.refine(reference_intensity, current_intensity, current.cloud, vgaIntrinsics(),
                        start, all, prior(0.01, 0.05));
  ASSERT_TRUE(weak.refined) << weak.message;
  const Eigen::Isometry3d weak_error = truth.inverse() * weak.T_reference_current;
  EXPECT_LT(weak_error.translation().norm(), 0.003);
  EXPECT_LT(pose_math::rotationAngle(weak_error), 0.1 * M_PI / 180);
  ASSERT_EQ(weak.information.rows(), 6);

  const PhotometricRefinement::Result strong =
      refinement.refine(reference_intensity, current_intensity, current.cloud, vgaIntrinsics(),
                        start, all, prior(1e-6, 1e-7));
  ASSERT_TRUE(strong.refined) << strong.message;
  // The tilt about x stays the start's; the motion along the wall is still found.
  EXPECT_NEAR(Eigen::AngleAxisd(strong.T_reference_current.linear()).axis().x() *
                  Eigen::AngleAxisd(strong.T_reference_current.linear()).angle(),
              0.5 * M_PI / 180, 0.02 * M_PI / 180);
  EXPECT_NEAR(strong.T_reference_current.translation().z(), 0.0, 1e-4);
  EXPECT_GT(strong.T_reference_current.translation().x(), 0.01);
}

TEST(MeasuredInformation, IsTheFlooredInverseOnTheMeasuredDirectionsAndZeroElsewhere) {
  Matrix6d covariance = Matrix6d::Identity() * 1e-6;
  covariance(0, 0) = covariance(1, 1) = covariance(5, 5) = 1.0;  // free along the wall
  Matrix6d floor = Matrix6d::Identity() * 3e-6;
  const Matrix6d information = measuredInformation(covariance, 1.0, 0.5, floor);
  for (int i : {0, 1, 5}) {
    EXPECT_NEAR(information.row(i).norm(), 0.0, 1e-9);
    EXPECT_NEAR(information.col(i).norm(), 0.0, 1e-9);
  }
  for (int i : {2, 3, 4})
    EXPECT_NEAR(information(i, i), 1.0 / 4e-6, 1e-3);  // 1 / (1e-6 + 3e-6)
  // Nothing measured: no information.
  EXPECT_TRUE(measuredInformation(Matrix6d::Identity(), 1.0, 0.5, floor).isZero());
}

TEST(PhotometricRefinement, AWallWithoutTextureLeavesTheStart) {
  const View reference = render(Eigen::Isometry3d::Identity(), true);
  const View current = render(motionAlongTheWall(0.03, 0.0, 0.0), true);
  const PhotometricRefinement::Result result =
      refineAlongTheWall(reference, current, Eigen::Isometry3d::Identity());
  EXPECT_FALSE(result.refined);
  EXPECT_NE(result.message.find("too few textured pixels"), std::string::npos) << result.message;
  EXPECT_TRUE(result.T_reference_current.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(PhotometricRefinement, ARefinementBeyondItsLimitIsRefused) {
  const View reference = render(Eigen::Isometry3d::Identity());
  const View current = render(motionAlongTheWall(0.04, 0.0, 0.0));
  PhotometricRefinement::Params params;
  params.max_translation = 0.01;  // the true 4 cm are beyond what may be taken
  const PhotometricRefinement::Result result =
      refineAlongTheWall(reference, current, Eigen::Isometry3d::Identity(), params);
  EXPECT_FALSE(result.refined);
  EXPECT_NE(result.message.find("too far"), std::string::npos) << result.message;
  EXPECT_TRUE(result.T_reference_current.isApprox(Eigen::Isometry3d::Identity()));
}

// A camera sliding along a textured wall at 1 cm a frame: the depth alone stays degenerate along
// the wall; with the images the tracker follows the slide.
double slideError(bool photometric, int* refined_frames) {
  OdometryTracker::Params params;
  params.photometric_refinement = photometric;
  OdometryTracker tracker(params);
  *refined_frames = 0;
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 20; ++i) {
    truth.translation() = Eigen::Vector3d(0.01 * i, 0.004 * i, 0.0);
    const View view = render(truth);
    const OdometryTracker::Result result =
        tracker.track(view.cloud, vgaIntrinsics(), i / 30.0, nullptr, &view.image);
    if (i > 0)  // (the first frame starts the odom frame: ok)
      EXPECT_EQ(result.status, TrackingStatus::kDegenerate) << "a wall constrains 3 directions";
    *refined_frames += result.photometric.refined ? 1 : 0;
  }
  return (tracker.pose().translation() - truth.translation()).norm();
}

TEST(OdometryTrackerPhotometric, FollowsASlideAlongATexturedWallThatTheDepthCannotSee) {
  int refined = 0;
  const double with_images = slideError(true, &refined);
  EXPECT_LT(with_images, 0.005);
  EXPECT_GE(refined, 15);
  const double depth_alone = slideError(false, &refined);
  EXPECT_EQ(refined, 0);
  EXPECT_GT(depth_alone, 0.05);  // 20 cm of slide, most of it unmeasured
}

TEST(PhotometricRefinement, IntensityJacobianMatchesNumericDifferentiation) {
  // An image known in closed form: I(x, y) and its gradient at any point.
  const double fx = 525, fy = 520, cx = 319.5, cy = 239.5;
  const auto image = [](double x, double y) {
    return 100 + 30 * std::sin(0.05 * x) + 20 * std::cos(0.08 * y) + 0.01 * x * y;
  };
  const auto gradient = [](double x, double y) {
    return Eigen::Vector2d(1.5 * std::cos(0.05 * x) + 0.01 * y,
                           -1.6 * std::sin(0.08 * y) + 0.01 * x);
  };
  const auto intensityAt = [&](const Eigen::Vector3d& P) {
    return image(fx * P.x() / P.z() + cx, fy * P.y() / P.z() + cy);
  };
  for (const Eigen::Vector3d& P : {Eigen::Vector3d(0.3, -0.2, 2.0), Eigen::Vector3d(-1.1, 0.4, 3.5),
                                   Eigen::Vector3d(0.05, 0.6, 0.9)}) {
    const Eigen::Vector2d g = gradient(fx * P.x() / P.z() + cx, fy * P.y() / P.z() + cy);
    const Eigen::Matrix<double, 1, 6> J = intensityJacobian(P, g.x(), g.y(), fx, fy);
    for (int i = 0; i < 6; ++i) {
      const double h = 1e-6;
      Vector6d xi = Vector6d::Zero();
      xi(i) = h;
      const Eigen::Vector3d plus = pose_math::retractLeft(xi, Eigen::Isometry3d::Identity()) * P;
      xi(i) = -h;
      const Eigen::Vector3d minus = pose_math::retractLeft(xi, Eigen::Isometry3d::Identity()) * P;
      const double numeric = (intensityAt(plus) - intensityAt(minus)) / (2 * h);
      EXPECT_NEAR(J(i), numeric, 1e-4 * std::max(1.0, std::abs(numeric)))
          << "column " << i << " at " << P.transpose();
    }
  }
}

TEST(PhotometricRefinement, FreeDirectionsAreTheCovariancesDegenerateOnes) {
  // sigma^2 H^-1 small on four directions, degenerate_variance on two mixed ones.
  Matrix6d Q = Matrix6d::Identity();
  const Eigen::Matrix<double, 6, 6> R =
      Eigen::HouseholderQR<Matrix6d>(Matrix6d::Random()).householderQ();
  Vector6d variances;
  variances << 1e-6, 2e-6, 1e-5, 4e-6, 100, 100;
  Q = R * variances.asDiagonal() * R.transpose();
  const PhotometricRefinement::Directions free = freeDirections(Q, 100, 0.5);
  ASSERT_EQ(free.cols(), 2);
  // The span of the two found equals the span of R's last two columns.
  const Matrix6d projector = free * free.transpose();
  EXPECT_LT((projector * R.col(4) - R.col(4)).norm(), 1e-9);
  EXPECT_LT((projector * R.col(5) - R.col(5)).norm(), 1e-9);
  EXPECT_LT((projector * R.col(0)).norm(), 1e-9);
  EXPECT_EQ(freeDirections(Matrix6d::Identity() * 1e-4, 100, 0.5).cols(), 0);
}

TEST(IntensityPyramid, HalvesEachLevelAndMeasuresGradientsPerPixel) {
  cv::Mat ramp(64, 80, CV_8UC1);
  for (int v = 0; v < ramp.rows; ++v)
    for (int u = 0; u < ramp.cols; ++u)
      ramp.at<std::uint8_t>(v, u) = static_cast<std::uint8_t>(2 * u + v);
  const IntensityPyramid pyramid = IntensityPyramid::fromImage(ramp, 3);
  ASSERT_EQ(pyramid.intensity.size(), 3u);
  EXPECT_EQ(pyramid.intensity[2].cols, 20);
  EXPECT_EQ(pyramid.intensity[2].rows, 16);
  // Inside the image the ramp rises 2 grey levels a pixel in u, 1 in v (level 0), twice that at
  // level 1.
  EXPECT_NEAR(pyramid.gradient_x[0].at<float>(30, 40), 2.0, 1e-5);
  EXPECT_NEAR(pyramid.gradient_y[0].at<float>(30, 40), 1.0, 1e-5);
  EXPECT_NEAR(pyramid.gradient_x[1].at<float>(15, 20), 4.0, 1e-4);
  EXPECT_THROW(IntensityPyramid::fromImage(cv::Mat(10, 10, CV_16UC1), 2), std::invalid_argument);
  EXPECT_THROW(IntensityPyramid::fromImage(ramp, 0), std::invalid_argument);
}

TEST(PhotometricRefinement, ParamsOutsideTheirRangesAreRefused) {
  PhotometricRefinement::Params params;
  params.huber = 0;
  EXPECT_THROW(PhotometricRefinement{params}, std::invalid_argument);
  params = PhotometricRefinement::Params();
  params.min_points = params.max_points + 1;
  EXPECT_THROW(PhotometricRefinement{params}, std::invalid_argument);
}

}  // namespace
}  // namespace quadric_slam

namespace quadric_slam {
namespace {

// Plane observations (the segmenter's) of the wall and of two surfaces across it, as a camera at
// T_reference_camera sees them; shift_x moves the plane x = 1 of the second to x = 1 + shift_x, as
// when the guess matches a surface to a different, parallel one.
std::vector<QuadricMeasurement> planesSeenFrom(const Eigen::Isometry3d& T_reference_camera,
                                               double shift_x) {
  const PlaneShape planes[] = {{Eigen::Vector3d::UnitZ(), synthetic::kWallZ},
                               {Eigen::Vector3d::UnitX(), 1.0 + shift_x},
                               {Eigen::Vector3d::UnitY(), 1.0}};
  std::vector<QuadricMeasurement> out;
  for (const PlaneShape& plane : planes) {
    const QuadricModel reference = quadricFromShape(plane);
    QuadricMeasurement m;
    m.quadric_camera =
        QuadricModel(reference.quadricClass(), T_reference_camera.inverse() * reference.pose(),
                     reference.scale());
    m.num_points = 5000;
    out.push_back(m);
  }
  return out;
}

// One step from the reference view to `truth` with the surfaces' guess made from observations
// whose plane x = 1 is shifted by guess_shift_x in the current frame; the tracker's result and
// its error against the truth (m).
OdometryTracker::Result stepWithGuess(const Eigen::Isometry3d& truth, double guess_shift_x,
                                      double* error) {
  OdometryTracker::Params params;
  params.photometric_refinement = true;
  OdometryTracker tracker(params);
  const View first = render(Eigen::Isometry3d::Identity());
  const std::vector<QuadricMeasurement> seen_first =
      planesSeenFrom(Eigen::Isometry3d::Identity(), 0.0);
  tracker.track(first.cloud, vgaIntrinsics(), 0.0, &seen_first, &first.image);
  const View second = render(truth);
  const std::vector<QuadricMeasurement> seen_second = planesSeenFrom(truth, guess_shift_x);
  const OdometryTracker::Result result =
      tracker.track(second.cloud, vgaIntrinsics(), 1.0 / 30, &seen_second, &second.image);
  *error = (truth.inverse() * tracker.pose()).translation().norm();
  return result;
}

// A step towards the textured wall too long for ICP from the prior, taken by the surfaces' guess.
// The depth fixes the distance and leaves the slide along the wall to the intensities, which are
// refined from the guess's pose and from the prior's; the better match is kept. A wrong match
// (the guess 30 cm off along the wall) is left for the prior's side; a right guess of a 25 cm
// slide, which the prior (no motion) is far from, is kept.
TEST(OdometryTrackerPhotometric, TheIntensitiesChooseBetweenTheGuessAndThePriorAlongTheWall) {
  Eigen::Isometry3d towards = Eigen::Isometry3d::Identity();
  towards.translation() = Eigen::Vector3d(0.01, 0.005, 0.4);
  double error = 0.0;
  const OdometryTracker::Result wrong_guess = stepWithGuess(towards, 0.3, &error);
  ASSERT_TRUE(wrong_guess.started_from_guess) << wrong_guess.guess.message;
  EXPECT_EQ(wrong_guess.status, TrackingStatus::kDegenerate);
  EXPECT_TRUE(wrong_guess.photometric.refined) << wrong_guess.photometric.message;
  EXPECT_LT(error, 0.005) << "refined where the wrong guess put it: 30 cm along the wall";

  Eigen::Isometry3d slide = towards;
  slide.translation().x() = 0.25;
  const OdometryTracker::Result right_guess = stepWithGuess(slide, 0.0, &error);
  ASSERT_TRUE(right_guess.started_from_guess) << right_guess.guess.message;
  EXPECT_LT(error, 0.005) << "the prior's side won against a right guess";
}

}  // namespace
}  // namespace quadric_slam

namespace quadric_slam {
namespace {

// A camera sliding along the textured wall at 4 cm a frame; after the first step two frames are
// dropped, so the next one arrives 16 cm along the wall. The depth stays degenerate along the wall
// and its alignments from the prior (constant velocity, scaled to the gap: right) and from the last
// pose (12 cm short) match the wall equally well, so the last pose wins the tie; the intensities,
// refined from there, may not move 12 cm (the refinement's 10 cm limit). They are refined from
// the alignment moved along its free directions to the prior's pose as well, and the better match
// is kept.
TEST(OdometryTrackerPhotometric, AfterDroppedFramesTheIntensitiesStartFromThePriorToo) {
  OdometryTracker::Params params;
  params.photometric_refinement = true;
  OdometryTracker tracker(params);
  const double stamps[] = {0.0, 1.0 / 30, 4.0 / 30};
  const double slide[] = {0.0, 0.04, 0.16};
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  OdometryTracker::Result result;
  for (int i = 0; i < 3; ++i) {
    truth.translation() = Eigen::Vector3d(slide[i], 0.3 * slide[i], 0.0);
    const View view = render(truth);
    result = tracker.track(view.cloud, vgaIntrinsics(), stamps[i], nullptr, &view.image);
  }
  EXPECT_EQ(result.status, TrackingStatus::kDegenerate);
  EXPECT_TRUE(result.photometric.refined) << result.photometric.message;
  const double error = (truth.inverse() * tracker.pose()).translation().norm();
  EXPECT_LT(error, 0.005) << "the step after the dropped frames ends " << error
                          << " m off (12 cm: where the last pose left it)";
}

}  // namespace
}  // namespace quadric_slam
