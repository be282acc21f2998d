#include <gtest/gtest.h>

#include <random>

#include "../test_support.h"
#include "quadric_slam/geometry/se3.h"

namespace quadric_slam {
namespace {

// Matrix exponential by its power series (reference for expSE3).
Eigen::Matrix4d seriesExp(const Eigen::Matrix4d& A) {
  Eigen::Matrix4d result = Eigen::Matrix4d::Identity(), term = Eigen::Matrix4d::Identity();
  for (int k = 1; k < 40; ++k) {
    term = term * A / k;
    result += term;
  }
  return result;
}

std::vector<Vector6d> sampleTwists() {
  std::mt19937 rng(7);
  std::vector<Vector6d> out;
  for (double angle : {0.0, 1e-9, 1e-4, 0.05, 0.099, 0.101, 0.5, 1.5, 2.5, 3.1}) {
    for (int i = 0; i < 3; ++i) {
      Vector6d xi;
      xi.head<3>() = test::randomVector(rng, 2.0);
      xi.tail<3>() = test::randomVector(rng, 1.0).normalized() * angle;
      out.push_back(xi);
    }
  }
  return out;
}

TEST(Se3, HatVeeRoundTrip) {
  for (const Vector6d& xi : sampleTwists())
    EXPECT_LT((vee(hat(xi)) - xi).norm(), 1e-15);
}

TEST(Se3, ExpMatchesMatrixSeries) {
  for (const Vector6d& xi : sampleTwists())
    EXPECT_LT((expSE3(xi).matrix() - seriesExp(hat(xi))).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(Se3, ExpLogRoundTrip) {
  for (const Vector6d& xi : sampleTwists()) {
    EXPECT_LT((logSE3(expSE3(xi)) - xi).norm(), 1e-10) << xi.transpose();
  }
}

TEST(Se3, AdjointMatchesConjugation) {
  std::mt19937 rng(3);
  for (int i = 0; i < 10; ++i) {
    const Eigen::Isometry3d T = test::randomPose(rng);
    const Vector6d xi = sampleTwists()[i * 3];
    const Eigen::Isometry3d lhs = T * expSE3(xi) * T.inverse();
    EXPECT_LT((lhs.matrix() - expSE3(adjointSE3(T) * xi).matrix()).norm(), 1e-12);
  }
}

TEST(Se3, JacobiansMatchNumeric) {
  for (const Vector6d& xi : sampleTwists()) {
    if (xi.tail<3>().norm() > 3.0)
      continue;  // near pi the logarithm's branch makes central differences meaningless
    const Eigen::Isometry3d T = expSE3(xi);
    const Eigen::MatrixXd Jl_inv = test::numericJacobian(
        [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
          return logSE3(expSE3(Vector6d(d)) * T);
        },
        6);
    const Eigen::MatrixXd Jr_inv = test::numericJacobian(
        [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
          return logSE3(T * expSE3(Vector6d(d)));
        },
        6);
    const Eigen::MatrixXd Jl = test::numericJacobian(
        [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
          return logSE3(expSE3(xi + Vector6d(d)) * T.inverse());
        },
        6);
    EXPECT_LT(test::relativeError(leftJacobianInverseSE3(xi), Jl_inv), 1e-6) << xi.transpose();
    EXPECT_LT(test::relativeError(rightJacobianInverseSE3(xi), Jr_inv), 1e-6) << xi.transpose();
    EXPECT_LT(test::relativeError(leftJacobianSE3(xi), Jl), 1e-6) << xi.transpose();
  }
}

TEST(Se3, PlusMinusRoundTrip) {
  std::mt19937 rng(11);
  for (const Vector6d& d : sampleTwists()) {
    const Eigen::Isometry3d T = test::randomPose(rng);
    EXPECT_LT((minus(plus(T, d), T) - d).norm(), 1e-10);          // body pair (eq. 14)
    EXPECT_LT((minusLeft(plusLeft(T, d), T) - d).norm(), 1e-10);  // world pair (eq. 11)
    const Eigen::Isometry3d T2 = test::randomPose(rng);
    EXPECT_LT((plus(T, minus(T2, T)).matrix() - T2.matrix()).norm(), 1e-10);
  }
}

TEST(Se3, PlusIsBodyFramePerturbation) {
  // T [+] xi moves the frame along its OWN axes: a pure rho = e_x moves the origin along T's x
  // axis.
  std::mt19937 rng(5);
  const Eigen::Isometry3d T = test::randomPose(rng);
  Vector6d xi = Vector6d::Zero();
  xi[0] = 0.3;
  const Eigen::Vector3d moved = plus(T, xi).translation() - T.translation();
  EXPECT_LT((moved - 0.3 * T.linear().col(0)).norm(), 1e-12);
}

}  // namespace
}  // namespace quadric_slam
