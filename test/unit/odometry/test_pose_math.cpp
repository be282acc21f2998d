#include <gtest/gtest.h>

#include <cmath>

#include "quadric_slam/odometry/pose_math.h"

namespace quadric_slam {
namespace {

using Vector6 = Vector6d;

Eigen::Isometry3d somePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.3, -1.2, 2.0);
  return T;
}

// The retraction agrees with geometry/se3.h's adjoint: exp((Ad_T xi)^) = T exp(xi^) T^-1, checked
// to first order with a small twist.
TEST(PoseMath, AdjointMovesPerturbationsBetweenFrames) {
  const Eigen::Isometry3d T = somePose();
  Vector6 xi;
  xi << 1e-6, -2e-6, 0.5e-6, 2e-6, 1e-6, -1.5e-6;
  const Eigen::Isometry3d lhs =
      pose_math::retractLeft(adjointSE3(T) * xi, Eigen::Isometry3d::Identity());
  const Eigen::Isometry3d rhs =
      T * pose_math::retractLeft(xi, Eigen::Isometry3d::Identity()) * T.inverse();
  EXPECT_LT((lhs.matrix() - rhs.matrix()).norm(), 1e-10);
}

TEST(PoseMath, RetractLeftIsExactRotationAndTranslation) {
  Vector6 xi;
  xi << 0.1, 0.2, -0.3, 0, 0, M_PI / 2;
  const Eigen::Isometry3d T = pose_math::retractLeft(xi, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(0.1, 0.2, -0.3)));
  EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
}

TEST(PoseMath, ScaleMotionScalesAngleAndTranslation) {
  const Eigen::Isometry3d T = somePose();
  const Eigen::Isometry3d half = pose_math::scaleMotion(T, 0.5);
  EXPECT_NEAR(pose_math::rotationAngle(half), 0.35, 1e-12);
  EXPECT_TRUE(half.translation().isApprox(T.translation() * 0.5));
  EXPECT_TRUE(pose_math::scaleMotion(T, 1.0).isApprox(T, 1e-12));
  EXPECT_TRUE(pose_math::scaleMotion(T, 0.0).isApprox(Eigen::Isometry3d::Identity()));
}

// A rotation that drifted off SO(3) (as repeated products and transposing inverses make it) is
// brought back; the translation is kept.
TEST(PoseMath, OrthonormalizedRepairsDriftedRotation) {
  Eigen::Isometry3d T = somePose();
  T.linear() *= 1.003;  // the 0.3 % scale error that once crept into a 150-frame run
  const Eigen::Isometry3d fixed = pose_math::orthonormalized(T);
  const Eigen::Matrix3d R = fixed.linear();
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_TRUE(fixed.translation().isApprox(T.translation()));
  EXPECT_NEAR(pose_math::rotationAngle(fixed.inverse() * somePose()), 0.0, 1e-9);
}

}  // namespace
}  // namespace quadric_slam
