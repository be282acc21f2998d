#include <gtest/gtest.h>

#include <random>

#include "../test_support.h"
#include "quadric_slam/geometry/manifolds.h"

namespace quadric_slam {
namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Checks Plus/Minus Jacobians against central differences and the [+]/[-] round trip at x.
void expectManifoldConsistent(const ceres::Manifold& m, const Eigen::VectorXd& x,
                              std::mt19937& rng) {
  const int n = m.AmbientSize(), k = m.TangentSize();
  // PlusJacobian = d Plus(x, d) / d d at d = 0
  RowMajor plus_j(n, k);
  ASSERT_TRUE(m.PlusJacobian(x.data(), plus_j.data()));
  const Eigen::MatrixXd plus_num = test::numericJacobian(
      [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
        Eigen::VectorXd out(n);
        m.Plus(x.data(), d.data(), out.data());
        return out;
      },
      k);
  EXPECT_LT(test::relativeError(plus_j, plus_num), 1e-6);
  // MinusJacobian = d Minus(y, x) / d y at y = x, along the manifold: (d Minus(Plus(x, d), x)/d d)
  // must be I, and along the ambient: compare with central differences in the ambient.
  RowMajor minus_j(k, n);
  ASSERT_TRUE(m.MinusJacobian(x.data(), minus_j.data()));
  const Eigen::MatrixXd minus_num = test::numericJacobian(
      [&](const Eigen::VectorXd& dy) -> Eigen::VectorXd {
        const Eigen::VectorXd y = x + dy;
        Eigen::VectorXd out(k);
        m.Minus(y.data(), x.data(), out.data());
        return out;
      },
      n);
  EXPECT_LT(test::relativeError(minus_j, minus_num), 1e-6);
  EXPECT_LT((minus_j * plus_j - Eigen::MatrixXd::Identity(k, k)).cwiseAbs().maxCoeff(), 1e-12);
  // Round trip Minus(Plus(x, d), x) = d for finite d.
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd d(k);
    for (int i = 0; i < k; ++i)
      d[i] = test::uniform(rng, -0.8, 0.8);
    Eigen::VectorXd y(n), back(k);
    m.Plus(x.data(), d.data(), y.data());
    // The round trip holds on the manifold: a quadric step must leave its scales positive (the
    // quadric Plus stops a scale at a thousandth of its value), so shorter steps until it does.
    while (n == kQuadricParameterSize && (y.tail<3>().array() < 0.5 * x.tail<3>().array()).any()) {
      d *= 0.5;
      m.Plus(x.data(), d.data(), y.data());
    }
    m.Minus(y.data(), x.data(), back.data());
    EXPECT_LT((back - d).norm(), 1e-10);
  }
}

TEST(PoseManifold, JacobiansMatchNumericAndRoundTrip) {
  std::mt19937 rng(21);
  PoseManifold m;
  for (int trial = 0; trial < 10; ++trial) {
    Eigen::VectorXd x(7);
    poseToParameters(test::randomPose(rng), x.data());
    expectManifoldConsistent(m, x, rng);
  }
}

void expectQuadricManifold(QuadricClass c, int seed) {
  std::mt19937 rng(seed);
  QuadricManifold m(c);
  EXPECT_EQ(m.TangentSize(), minimalDimension(c));
  for (int trial = 0; trial < 10; ++trial) {
    const QuadricModel q = test::randomQuadric(c, rng);
    Eigen::VectorXd x(10);
    quadricToParameters(q, x.data());
    expectManifoldConsistent(m, x, rng);
    // Plus keeps the class's scale ties (Table II).
    Eigen::VectorXd d = Eigen::VectorXd::Constant(m.TangentSize(), 0.1), y(10);
    m.Plus(x.data(), d.data(), y.data());
    EXPECT_NO_THROW(quadricFromParameters(y.data(), c, q.signature()));
  }
}

TEST(PlaneManifold, JacobiansMatchNumericAndRoundTrip) {
  expectQuadricManifold(QuadricClass::kPlane, 1);
}
TEST(SphereManifold, JacobiansMatchNumericAndRoundTrip) {
  expectQuadricManifold(QuadricClass::kSphere, 2);
}
TEST(CylinderManifold, JacobiansMatchNumericAndRoundTrip) {
  expectQuadricManifold(QuadricClass::kCylinder, 3);
}
TEST(ConeManifold, JacobiansMatchNumericAndRoundTrip) {
  expectQuadricManifold(QuadricClass::kCone, 4);
}
TEST(GeneralManifold, JacobiansMatchNumericAndRoundTrip) {
  expectQuadricManifold(QuadricClass::kGeneral, 5);
}

TEST(QuadricManifold, TangentMovesFollowTableTwo) {
  // A cylinder's tangent (rho1, rho2, phi1, phi2, alpha) never moves along or rotates about its
  // own axis; a plane's (rho1, phi2, phi3) only moves along its normal or tilts it.
  std::mt19937 rng(8);
  const QuadricModel cyl = test::randomQuadric(QuadricClass::kCylinder, rng);
  const Eigen::Vector3d axis = cyl.pose().linear().col(2);
  Eigen::VectorXd d(5);
  d << 0.2, -0.1, 0, 0, 0;  // translation only
  const QuadricModel moved = cyl.plusMinimal(d);
  EXPECT_NEAR((moved.pose().translation() - cyl.pose().translation()).dot(axis), 0, 1e-12);
  const QuadricModel plane = test::randomQuadric(QuadricClass::kPlane, rng);
  Eigen::VectorXd dp(3);
  dp << 0.3, 0, 0;
  const Eigen::Vector3d shift =
      plane.plusMinimal(dp).pose().translation() - plane.pose().translation();
  EXPECT_LT((shift - 0.3 * plane.pose().linear().col(0)).norm(), 1e-12);
}

TEST(QuadricManifold, AStepCannotTakeARadiusThroughZero) {
  // A cylinder of radius 0.05 m: its tangent (rho1, rho2, phi1, phi2, alpha) with alpha the
  // radius' step. S must stay in D^3 (positive): a step through zero stops at a thousandth of the
  // radius, and Plus still succeeds (Ceres ends a solve whose projected-gradient step fails).
  const QuadricManifold manifold(QuadricClass::kCylinder);
  Eigen::VectorXd x(kQuadricParameterSize);
  x << 0.1, -0.2, 1.5, 0, 0, 0, 1, 0.05, 0.05, 1;
  Eigen::VectorXd d = Eigen::VectorXd::Zero(5), out(kQuadricParameterSize);
  d[4] = 0.03;
  EXPECT_TRUE(manifold.Plus(x.data(), d.data(), out.data()));
  EXPECT_NEAR(out[7], 0.08, 1e-12);
  for (const double step : {-0.05, -0.07, -3.0}) {
    d[4] = step;
    EXPECT_TRUE(manifold.Plus(x.data(), d.data(), out.data()));
    EXPECT_NEAR(out[7], 0.05e-3, 1e-15) << step;
    EXPECT_EQ(out[8], out[7]);
    EXPECT_EQ(out[9], 1.0);  // the cylinder's axis scale does not move
    EXPECT_NO_THROW(
        quadricFromParameters(out.data(), QuadricClass::kCylinder, Eigen::Vector4d(1, 1, 0, -1)));
  }
}

}  // namespace
}  // namespace quadric_slam
