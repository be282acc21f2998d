#include <gtest/gtest.h>

#include <random>

#include "../test_support.h"
#include "quadric_slam/geometry/symmetry.h"

namespace quadric_slam {
namespace {

void expectSurfaceMinusInvariant(QuadricClass c, int seed) {
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 20; ++trial) {
    const QuadricModel a = test::randomQuadric(c, rng);
    const Eigen::Isometry3d G = test::randomSymmetry(c, rng);
    const QuadricModel same(c, a.pose() * G, a.scale(), a.signature());
    // Same surface (same Q), different frame: zero difference.
    ASSERT_LT((same.matrix() - a.matrix()).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT(surfaceMinus(a, same).norm(), 1e-9) << toString(c) << " trial " << trial;
    // A different surface: the difference does not depend on the frame chosen for it.
    Eigen::VectorXd d(minimalDimension(c));
    for (int i = 0; i < d.size(); ++i)
      d[i] = test::uniform(rng, -0.2, 0.2);
    const QuadricModel b = a.plusMinimal(d);
    const QuadricModel b_other(c, b.pose() * test::randomSymmetry(c, rng), b.scale(), b.signature());
    EXPECT_LT((surfaceMinus(a, b) - surfaceMinus(a, b_other)).norm(), 1e-9);
    // ... and it recovers the minimal displacement that made b from a, up to sign.
    EXPECT_LT((surfaceMinus(b, a) - d).norm(), 1e-9) << toString(c) << " trial " << trial;
  }
}

TEST(SphereSymmetry, SurfaceMinusInvariantToRotation) {
  expectSurfaceMinusInvariant(QuadricClass::kSphere, 31);
}
TEST(CylinderSymmetry, SurfaceMinusInvariantToAxisRotationSlideAndFlip) {
  expectSurfaceMinusInvariant(QuadricClass::kCylinder, 32);
}
TEST(ConeSymmetry, SurfaceMinusInvariantToAxisRotationAndFlip) {
  expectSurfaceMinusInvariant(QuadricClass::kCone, 33);
}
TEST(PlaneSymmetry, SurfaceMinusInvariantToInPlaneMotionAndFlip) {
  expectSurfaceMinusInvariant(QuadricClass::kPlane, 34);
}
TEST(GeneralSymmetry, SurfaceMinusInvariantToAxisFlips) {
  expectSurfaceMinusInvariant(QuadricClass::kGeneral, 35);
}

TEST(SymmetryAlignment, JacobianMatchesNumeric) {
  // e(delta) = log(G(D exp(delta))^-1 D exp(delta)): the aligned error with G re-solved.
  std::mt19937 rng(36);
  for (QuadricClass c : kAllQuadricClasses) {
    for (int trial = 0; trial < 10; ++trial) {
      Vector6d xi;
      xi.head<3>() = test::randomVector(rng, 0.5);
      xi.tail<3>() = test::randomVector(rng, 0.4);
      const Eigen::Isometry3d D = expSE3(xi) * test::randomSymmetry(c, rng);
      auto aligned = [&](const Eigen::Isometry3d& Dp) -> Vector6d {
        return logSE3(symmetryAlignment(c, Dp).inverse() * Dp);
      };
      const Vector6d e = aligned(D);
      for (int idx : classDefinition(c).dropped_pose_indices)
        EXPECT_NEAR(e[idx], 0, 1e-12);
      const Eigen::MatrixXd num = test::numericJacobian(
          [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
            return aligned(plus(D, Vector6d(d)));
          },
          6);
      EXPECT_LT(test::relativeError(alignedErrorJacobian(c, e), num), 1e-6) << toString(c);
    }
  }
}

}  // namespace
}  // namespace quadric_slam

namespace quadric_slam {
namespace {

TEST(SymmetryAlignment, MinimalAdjointIsARepresentation) {
  // M(G1 G2) = M(G1) M(G2) and M(G^-1) = M(G)^-1 on each class's minimal space: the symmetries
  // preserve the kept subspace, so covariances can be carried between frames exactly.
  std::mt19937 rng(37);
  for (QuadricClass c : kAllQuadricClasses) {
    for (int trial = 0; trial < 10; ++trial) {
      const Eigen::Isometry3d G1 = test::randomSymmetry(c, rng), G2 = test::randomSymmetry(c, rng);
      const Eigen::MatrixXd M12 = minimalAdjoint(c, G1 * G2);
      EXPECT_LT((M12 - minimalAdjoint(c, G1) * minimalAdjoint(c, G2)).cwiseAbs().maxCoeff(), 1e-9)
          << toString(c);
      EXPECT_LT((minimalAdjoint(c, G1.inverse()) * minimalAdjoint(c, G1) -
                 Eigen::MatrixXd::Identity(M12.rows(), M12.cols()))
                    .cwiseAbs()
                    .maxCoeff(),
                1e-9);
    }
  }
}

}  // namespace
}  // namespace quadric_slam
