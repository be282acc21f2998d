// A general quadric's axis relabellings (geometry/symmetry.h): each describes the same surface,
// minimalAdjoint carries a perturbation (and so a covariance) across one exactly, alignment picks
// the relabelling that matches a reference's axes, and surfaceMinus of two frames of one ellipsoid
// with permuted axes is zero.
#include <gtest/gtest.h>

#include <random>

#include "../test_support.h"
#include "quadric_slam/geometry/symmetry.h"

namespace quadric_slam {
namespace {

const Eigen::Vector4d kEllipsoid(1, 1, 1, -1);
const Eigen::Vector4d kOneSheet(1, 1, -1, -1);
const Eigen::Vector4d kTwoSheets(1, 1, -1, 1);

double matrixDifference(const QuadricModel& a, const QuadricModel& b) {
  const Eigen::Matrix4d A = a.matrix() / a.matrix().norm(), B = b.matrix() / b.matrix().norm();
  return std::min((A - B).cwiseAbs().maxCoeff(), (A + B).cwiseAbs().maxCoeff());
}

QuadricModel randomGeneral(std::mt19937& rng, const Eigen::Vector4d& signature) {
  return QuadricModel(QuadricClass::kGeneral, test::randomPose(rng),
                      Eigen::Vector3d(test::uniform(rng, 2, 5), test::uniform(rng, 6, 9),
                                      test::uniform(rng, 11, 14)),
                      signature);
}

TEST(GeneralRelabelling, CountsFollowTheSignature) {
  EXPECT_EQ(generalAxisRelabellings(kEllipsoid).size(), 24u);
  EXPECT_EQ(generalAxisRelabellings(kOneSheet).size(), 8u);  // the two +1 axes may swap
  EXPECT_EQ(generalAxisRelabellings(kTwoSheets).size(), 8u);
  for (const Eigen::Matrix3d& P : generalAxisRelabellings(kEllipsoid)) {
    EXPECT_NEAR(P.determinant(), 1.0, 1e-12);
    EXPECT_LT((P.transpose() * P - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  }
  EXPECT_TRUE(generalAxisRelabellings(kEllipsoid).front().isIdentity());
}

TEST(GeneralRelabelling, EveryRelabellingIsTheSameSurface) {
  std::mt19937 rng(41);
  for (const Eigen::Vector4d& sigma : {kEllipsoid, kOneSheet, kTwoSheets}) {
    const QuadricModel q = randomGeneral(rng, sigma);
    for (const Eigen::Matrix3d& P : generalAxisRelabellings(sigma)) {
      const QuadricModel same = withSymmetry(q, makeIsometry(P, Eigen::Vector3d::Zero()));
      EXPECT_LT(matrixDifference(q, same), 1e-12) << sigma.transpose();
    }
  }
}

TEST(GeneralRelabelling, MinimalAdjointCarriesPerturbationsAcross) {
  // q [+] x and (q G) [+] M x, M = minimalAdjoint(G^-1), are one surface: the covariance rule
  // C' = M C M^T of the segmenter, the merger and the factors is exact for relabellings.
  std::mt19937 rng(42);
  for (int trial = 0; trial < 10; ++trial) {
    const QuadricModel q = randomGeneral(rng, kEllipsoid);
    Eigen::VectorXd x(9);
    for (int i = 0; i < 9; ++i)
      x[i] = test::uniform(rng, -0.3, 0.3);
    for (const Eigen::Matrix3d& P : generalAxisRelabellings(kEllipsoid)) {
      const Eigen::Isometry3d G = makeIsometry(P, Eigen::Vector3d::Zero());
      const Eigen::VectorXd x_g = minimalAdjoint(QuadricClass::kGeneral, G.inverse()) * x;
      EXPECT_LT(matrixDifference(q.plusMinimal(x), withSymmetry(q, G).plusMinimal(x_g)), 1e-12);
    }
  }
}

TEST(GeneralRelabelling, AlignmentUndoesAnyRelabelling) {
  std::mt19937 rng(43);
  for (int trial = 0; trial < 10; ++trial) {
    const QuadricModel a = randomGeneral(rng, kEllipsoid);
    Eigen::VectorXd d(9);
    for (int i = 0; i < 9; ++i)
      d[i] = test::uniform(rng, -0.05, 0.05);
    const QuadricModel b = a.plusMinimal(d);
    for (const Eigen::Matrix3d& P : generalAxisRelabellings(kEllipsoid)) {
      const Eigen::Isometry3d G = makeIsometry(P, Eigen::Vector3d::Zero());
      const QuadricModel b_relabelled = withSymmetry(b, G);
      const QuadricModel aligned = alignToReference(b_relabelled, a);
      // Back in a's axis order (b's own frame): the scales and the axes match b's.
      EXPECT_LT((aligned.scale() - b.scale()).norm(), 1e-12);
      EXPECT_LT((aligned.pose().linear() - b.pose().linear()).norm(), 1e-9);
      // The surface difference is the one that made b, whatever frame b is given in: -d in a's
      // frame, d carried into b's relabelled frame in b's.
      EXPECT_LT((surfaceMinus(a, b_relabelled) + d).norm(), 1e-9);
      EXPECT_LT((surfaceMinus(b_relabelled, a) -
                 minimalAdjoint(QuadricClass::kGeneral, G.inverse()) * d)
                    .norm(),
                1e-9);
      EXPECT_LT(surfaceMinus(a, withSymmetry(a, G)).norm(), 1e-9);
    }
  }
}

}  // namespace
}  // namespace quadric_slam
