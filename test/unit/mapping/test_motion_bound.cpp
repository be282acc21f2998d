// The camera's speed bound on an odometry increment's covariance (mapping/motion_bound.h): no
// larger than the reported covariance, no larger than the motion bound, unchanged within it.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "quadric_slam/mapping/motion_bound.h"

namespace quadric_slam {
namespace {

// A - B is positive semi-definite (up to rounding relative to A's size).
bool atLeast(const Matrix6d& A, const Matrix6d& B) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(0.5 * ((A - B) + (A - B).transpose()));
  return eigen.eigenvalues().minCoeff() >= -1e-9 * A.norm();
}

Matrix6d diagonal(double t2, double r2) {
  return (Vector6d() << t2, t2, t2, r2, r2, r2).finished().asDiagonal();
}

Matrix6d randomCovariance(std::mt19937* rng, double t_sigma, double r_sigma) {
  std::normal_distribution<double> n(0.0, 1.0);
  Matrix6d A;
  for (int i = 0; i < 36; ++i)
    A(i / 6, i % 6) = n(*rng);
  const Vector6d s = (Vector6d() << t_sigma, t_sigma, t_sigma, r_sigma, r_sigma, r_sigma).finished();
  return s.asDiagonal() * (A * A.transpose() + 0.1 * Matrix6d::Identity()) * s.asDiagonal();
}

TEST(MotionBound, ATrackedFrameIsUnchanged) {
  // A good frame at 30 Hz: millimetres and milliradians against 3.3 cm and 67 mrad.
  const Matrix6d tracked = diagonal(1e-6, 1e-6);
  EXPECT_TRUE(boundIncrementCovariance(tracked, 1.0 / 30, 1.0, 2.0).isApprox(tracked));
}

TEST(MotionBound, ALostFrameGetsTheMotionBound) {
  // A lost frame's 1 m^2 / 1 rad^2 in every direction, 0.1 s: the bound itself.
  const Matrix6d bounded = boundIncrementCovariance(Matrix6d::Identity(), 0.1, 1.0, 2.0);
  EXPECT_TRUE(bounded.isApprox(diagonal(0.01, 0.04), 1e-9)) << bounded;
}

TEST(MotionBound, ADegenerateDirectionIsClampedTheOthersKept) {
  // Degenerate along x (sliding along a wall): only that direction changes.
  Matrix6d degenerate = diagonal(1e-6, 1e-6);
  degenerate(0, 0) = 1.0;
  const Matrix6d bounded = boundIncrementCovariance(degenerate, 1.0 / 30, 1.0, 2.0);
  EXPECT_NEAR(bounded(0, 0), 1.0 / 900, 1e-12);
  Matrix6d rest = bounded;
  rest(0, 0) = degenerate(0, 0);
  EXPECT_TRUE(rest.isApprox(degenerate, 1e-9)) << bounded;
}

TEST(MotionBound, NeverLargerThanEitherTheReportOrTheBound) {
  std::mt19937 rng(7);
  for (int i = 0; i < 200; ++i) {
    const double dt = 0.02 + 0.05 * (i % 10);
    const Matrix6d reported = randomCovariance(&rng, i % 2 ? 0.5 : 0.01, i % 3 ? 0.5 : 0.01);
    const Matrix6d bounded = boundIncrementCovariance(reported, dt, 1.0, 2.0);
    EXPECT_TRUE(atLeast(reported, bounded)) << "case " << i;
    EXPECT_TRUE(atLeast(diagonal(dt * dt, 4 * dt * dt), bounded)) << "case " << i;
    EXPECT_TRUE(bounded.isApprox(bounded.transpose()));
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix6d>(bounded).eigenvalues().minCoeff(), 0.0);
  }
}

TEST(MotionBound, NoBoundWithoutTimeOrSpeed) {
  const Matrix6d lost = Matrix6d::Identity();
  EXPECT_TRUE(boundIncrementCovariance(lost, 0.0, 1.0, 2.0).isApprox(lost));
  EXPECT_TRUE(boundIncrementCovariance(lost, -0.1, 1.0, 2.0).isApprox(lost));
  EXPECT_TRUE(boundIncrementCovariance(lost, 0.1, 0.0, 2.0).isApprox(lost));
  EXPECT_TRUE(boundIncrementCovariance(lost, 0.1, 1.0, 0.0).isApprox(lost));
}

}  // namespace
}  // namespace quadric_slam
