// Which ICP alignment the tracker keeps (odometry/alignment_choice.h): the better one by inliers
// and residual, and an alignment from the surfaces' guess over the prior's only where the depth
// backs the guess along the directions it constrains; of photometric refinements from several
// starts, the better intensity match.
#include <gtest/gtest.h>

#include "quadric_slam/odometry/alignment_choice.h"

namespace quadric_slam {
namespace {

PointToPlaneIcp::Result alignment(TrackingStatus status, int correspondences, int dof,
                                  double rms = 0.003) {
  PointToPlaneIcp::Result r;
  r.status = status;
  r.correspondences = correspondences;
  r.constrained_dof = dof;
  r.rms_residual = rms;
  return r;
}

constexpr TrackingStatus kOk = TrackingStatus::kOk;
constexpr TrackingStatus kDegenerate = TrackingStatus::kDegenerate;
constexpr TrackingStatus kLost = TrackingStatus::kLost;

TEST(AlignmentChoice, BetterMeansNotLostThenMoreInliersThenSmallerResidual) {
  EXPECT_TRUE(betterAlignment(alignment(kDegenerate, 500, 3), alignment(kLost, 9000, 6)));
  EXPECT_FALSE(betterAlignment(alignment(kLost, 9000, 6), alignment(kDegenerate, 500, 3)));
  EXPECT_TRUE(betterAlignment(alignment(kOk, 10300, 6), alignment(kOk, 10000, 6)));
  EXPECT_FALSE(betterAlignment(alignment(kOk, 10000, 6), alignment(kOk, 10300, 6)));
  // Within 2% of each other the residual decides.
  EXPECT_TRUE(betterAlignment(alignment(kOk, 10000, 6, 0.002), alignment(kOk, 10100, 6, 0.003)));
  EXPECT_FALSE(betterAlignment(alignment(kOk, 10100, 6, 0.003), alignment(kOk, 10000, 6, 0.002)));
}

TEST(AlignmentChoice, AnOkOrBetterThanLostGuessAlignmentReplacesWhenBetter) {
  EXPECT_TRUE(guessAlignmentReplaces(alignment(kOk, 10000, 6), alignment(kDegenerate, 9000, 5)));
  EXPECT_TRUE(guessAlignmentReplaces(alignment(kDegenerate, 2000, 3), alignment(kLost, 1400, 4)));
  // Not better: the prior's stays, whatever the guess's status.
  EXPECT_FALSE(guessAlignmentReplaces(alignment(kOk, 9000, 6), alignment(kOk, 10000, 6)));
}

TEST(AlignmentChoice, ADegenerateGuessAlignmentNeedsTheDepthBehindIt) {
  // More constrained directions: a desk's top and side matched from the guess, its top alone
  // from a prior 10 cm off (5 of 6 against 3 of 6).
  EXPECT_TRUE(
      guessAlignmentReplaces(alignment(kDegenerate, 12730, 5), alignment(kDegenerate, 8270, 3)));
  // As many directions and clearly more points (8%).
  EXPECT_TRUE(
      guessAlignmentReplaces(alignment(kDegenerate, 9800, 4), alignment(kDegenerate, 9085, 4)));
  // One direction fewer but clearly more points: the prior's converged elsewhere.
  EXPECT_TRUE(
      guessAlignmentReplaces(alignment(kDegenerate, 9785, 4), alignment(kDegenerate, 9085, 5)));
  // Better by inliers, but within the 5% margin at as many or fewer directions: a surface matched
  // to a parallel one slides the guess's start along it.
  EXPECT_FALSE(
      guessAlignmentReplaces(alignment(kDegenerate, 9300, 4), alignment(kDegenerate, 9085, 4)));
  EXPECT_FALSE(
      guessAlignmentReplaces(alignment(kDegenerate, 9400, 4), alignment(kDegenerate, 9085, 5)));
  // Two directions fewer: never, however many more points.
  EXPECT_FALSE(
      guessAlignmentReplaces(alignment(kDegenerate, 20000, 3), alignment(kDegenerate, 9085, 5)));
}

// A wall facing the camera along z leaves v_x, v_y and omega_z free; a degenerate alignment from
// the surfaces' guess keeps the depth's distance and tilts but the prior's slide and turn.
TEST(AlignmentChoice, TheFreeDirectionsOfAGuessAlignmentAreThePriors) {
  Eigen::Isometry3d prior = Eigen::Isometry3d::Identity();
  prior.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  prior.translation() = Eigen::Vector3d(0.5, -0.2, 1.0);
  Vector6d step;
  step << 0.25, -0.1, 0.02, 0.01, -0.015, 0.2;  // 27 cm and 11 degrees along the free directions
  const Eigen::Isometry3d aligned = pose_math::retractLeft(step, prior);
  Eigen::Matrix<double, 6, Eigen::Dynamic> free = Eigen::Matrix<double, 6, 3>::Zero();
  free(0, 0) = free(1, 1) = free(5, 2) = 1;

  const Eigen::Isometry3d kept = priorAlongFreeDirections(aligned, prior, free);
  Vector6d expected_step = Vector6d::Zero();
  expected_step(2) = 0.02;
  expected_step(3) = 0.01;
  expected_step(4) = -0.015;
  EXPECT_TRUE(kept.isApprox(pose_math::retractLeft(expected_step, prior), 1e-9));
  // Nothing free: the alignment as it is.
  EXPECT_TRUE(priorAlongFreeDirections(aligned, prior, Eigen::Matrix<double, 6, 0>())
                  .isApprox(aligned, 1e-9));
}

PhotometricRefinement::Result refinement(int points, double rms_after) {
  PhotometricRefinement::Result r;
  r.refined = true;
  r.points = points;
  r.rms_after = rms_after;
  return r;
}

TEST(AlignmentChoice, TheBetterPhotometricMatchHasTheLowerRmsOverComparablePixels) {
  EXPECT_TRUE(betterPhotometricMatch(refinement(2400, 9.0), refinement(2380, 13.1)));
  EXPECT_FALSE(betterPhotometricMatch(refinement(2380, 13.1), refinement(2400, 9.0)));
  // A start that leaves only a few pixels in the keyframe's view does not win by their RMS.
  EXPECT_FALSE(betterPhotometricMatch(refinement(1000, 5.0), refinement(2400, 9.0)));
  EXPECT_TRUE(betterPhotometricMatch(refinement(2400, 9.0), refinement(1000, 5.0)));
}

}  // namespace
}  // namespace quadric_slam
